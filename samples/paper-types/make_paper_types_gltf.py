#!/usr/bin/env python3
"""Writes samples/paper-types/cylinder-fold.gltf: the handle curves of the
paper-types sample (paper Fig. 21: "The same experiment as in Figure 1 is
performed with different values of the allowed compression factor eps_c:
from left to right, 1%, 0.5%, and 0.2%"; Sec. 7.3: "while keeping the same
handle animation scenario").

The motion is the cylinder-fold sample's, exactly: this script writes
samples/cylinder-fold/make_cylinder_fold_gltf.py's tracks() into this
folder, so the two files are identical but for the generator string. Read
that script's docstring for the curves. The three scene files of this
folder (eps-1.0.toml, eps-0.5.toml, eps-0.2.toml) share this file.

Run it to regenerate the file (the committed file is its output):
    python3 samples/paper-types/make_paper_types_gltf.py [OUT.gltf]
"""
import os
import sys

# Shared helpers (samples/gltf_anim.py).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from gltf_anim import write_sample_of  # noqa: E402


def main():
    write_sample_of(__file__, os.path.join("..", "cylinder-fold", "make_cylinder_fold_gltf.py"),
                    "cylinder-fold.gltf")


if __name__ == "__main__":
    main()
