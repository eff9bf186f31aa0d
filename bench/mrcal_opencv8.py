#!/usr/bin/python3
"""kincal's regularised 8-coefficient model against mrcal's OPENCV8.

Runs where mrcal is installed (see bench/mrcal_compare.py). `kincal camcal
--distortion 8 --loss none --reject-sigma 0 --no-board-warp` (plain least
squares plus
kincal's k4..k6 regulariser) on OpenCV's stereo pairs; then mrcal.optimize with mrcal's own
regularisation on the same corners (no outlier rejection), seeded by
kincal's solution. Prints fx, cx, cy and the distortion of both.

Usage (from the worktree root, after building):
  /usr/bin/python3 bench/mrcal_opencv8.py [--kincal build/bin/kincal]
      [--data ../shared/data/opencv-stereo-left-right]
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

import mrcal
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mrcal_compare  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--kincal", default="build/bin/kincal")
    parser.add_argument("--data",
                        default="../shared/data/opencv-stereo-left-right")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as out_dir:
        cmd = [args.kincal, "camcal", "--left", args.data + "/left*.jpg",
               "--right", args.data + "/right*.jpg", "--target",
               "chessboard:9x6:1", "--loss", "none", "--reject-sigma", "0",
               "--no-board-warp", "--distortion", "8",
               "--out", os.path.join(out_dir, "rig.yaml"), "--json"]
        summary = json.loads(subprocess.run(
            cmd, check=True, capture_output=True, text=True).stdout)
    print("kincal: %s after %d iterations, regulariser share %.3g"
          % (summary["termination"], summary["iterations"],
             summary["regularization"]["share"]))
    inputs, _ = mrcal_compare.mrcal_solve(summary, summary["images"])
    inputs["do_apply_regularization"] = True
    mrcal.optimize(**inputs)
    for cam, row in zip(summary["cameras"], inputs["intrinsics"]):
        print("%-5s kincal fx %.3f cx %.3f cy %.3f k %s" % (
            cam["name"], cam["fx"], cam["cx"], cam["cy"],
            np.round(cam["distortion"], 4)))
        print("%-5s mrcal  fx %.3f cx %.3f cy %.3f k %s" % (
            cam["name"], row[0], row[2], row[3], np.round(row[4:], 4)))


if __name__ == "__main__":
    main()
