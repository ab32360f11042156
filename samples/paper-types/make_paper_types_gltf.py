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
import importlib.util
import os
import sys

# Shared helpers (samples/gltf_anim.py).
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))
from gltf_anim import sample_path, write_sample  # noqa: E402


def main():
    source = os.path.join(HERE, "..", "cylinder-fold", "make_cylinder_fold_gltf.py")
    spec = importlib.util.spec_from_file_location("make_cylinder_fold_gltf", source)
    cylinder_fold = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(cylinder_fold)
    # The generator names both scripts.
    write_sample(__file__, "cylinder-fold.gltf", *cylinder_fold.tracks(),
                 generator="crumple %s (%s)" % (sample_path(__file__), sample_path(source)))


if __name__ == "__main__":
    main()
