#!/usr/bin/env python3
"""Writes samples/crumple-closeup/cylinder-fold.gltf: the handle curves of the
crumple-closeup sample, a 1920 x 1080 close-up of the cylinder-fold motion
(paper Fig. 1 and Sec. 7.3: a sheet wrapped smoothly into a tube, then bent
across the tube's axis until singular points form).

The motion is the cylinder-fold sample's, exactly: this script writes
samples/cylinder-fold/make_cylinder_fold_gltf.py's tracks() into this
folder, so the two files are identical but for the generator string. Read
that script's docstring for the curves.

Run it to regenerate the file (the committed file is its output):
    python3 samples/crumple-closeup/make_crumple_closeup_gltf.py [OUT.gltf]
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
