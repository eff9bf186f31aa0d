#!/usr/bin/python3
"""kincal's default camcal against mrcal's default: outliers, consistency.

Runs where mrcal is installed (see bench/mrcal_compare.py). On OpenCV's
stereo pairs:

1. `kincal camcal --json` with kincal's defaults (or the extra options given
   with --kincal-args) reports its outlier rejection and its even/odd
   cross-validation: the projection difference between the solves on the
   even and on the odd views, rays at infinity, the best rotation fitted on
   the pixels within the focus radius (160 px, a third of the 480 px
   height) of the image centre; RMS within that radius and over the whole
   image (mrcal.projection_diff with use_uncertainties=False).
2. mrcal's default (mrcal.optimize with outlier rejection, regularisation
   and the board deflection calobject_warp as mrcal-calibrate-cameras solves
   it, OPENCV5; without the warp when --no-board-warp is among the kincal
   options) on the same corners, seeded by kincal's
   solution: all views, even views, odd views. The same projection
   difference, computed by mrcal.projection_diff, between mrcal's halves
   and between kincal's halves (kincal run on the even and the odd pairs,
   written as .cameramodel files), so both numbers come from mrcal's code.
3. kincal's intrinsics against mrcal's default solution in units of
   mrcal's sigma (covariance of the solve, inv(J^T J) times the variance of
   the inlier residuals, unpacked to the state's units).
4. Where the whole-image difference comes from: its RMS inside and outside
   the convex hull of the corners each camera saw, and the share of the
   squared difference outside that hull (the image the boards never
   covered, where only the distortion polynomial's extrapolation speaks).

Exit 1 when kincal's halves (as mrcal computes the difference) agree worse
than mrcal's by more than 0.005 px within the focus radius or 5 % over the
whole image, or an intrinsic is 3 sigma or more from mrcal's.

Usage (from the worktree root, after building):
  /usr/bin/python3 bench/mrcal_crossval.py [--kincal build/bin/kincal]
      [--data ../shared/data/opencv-stereo-left-right]
      [--kincal-args '--reject-sigma 4 ...']
"""

import argparse
import glob
import json
import os
import shlex
import subprocess
import sys
import tempfile

import mrcal
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mrcal_compare  # noqa: E402

FOCUS_RADIUS_PX = 160


def run_kincal(kincal, left, right, out_dir, extra):
    cmd = [kincal, "camcal", "--left", left, "--right", right,
           "--target", "chessboard:9x6:1",
           "--out", os.path.join(out_dir, "rig.yaml"),
           "--out-cameramodel", os.path.join(out_dir, "kincal"),
           "--json"] + extra
    out = subprocess.run(cmd, check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def half_dirs(data, out_dir):
    """Even and odd stereo pairs (in name order) as symlinks in two folders."""
    lefts = sorted(glob.glob(os.path.join(data, "left*.jpg")))
    rights = sorted(glob.glob(os.path.join(data, "right*.jpg")))
    dirs = []
    for h in range(2):
        d = os.path.join(out_dir, "half%d" % h)
        os.makedirs(d)
        for path in lefts[h::2] + rights[h::2]:
            os.symlink(os.path.abspath(path),
                       os.path.join(d, os.path.basename(path)))
        dirs.append(d)
    return dirs


def diff_rms(models):
    """RMS projection difference within the focus radius and over the image."""
    w, h = models[0].imagersize()
    centre = np.array([(w - 1) / 2.0, (h - 1) / 2.0])
    difference, _, q0, _ = mrcal.projection_diff(
        models, use_uncertainties=False, focus_center=centre,
        focus_radius=FOCUS_RADIUS_PX)
    inside = np.linalg.norm(q0 - centre, axis=-1) <= FOCUS_RADIUS_PX
    return (float(np.sqrt(np.mean(difference[inside] ** 2))),
            float(np.sqrt(np.mean(difference ** 2))))


def coverage_split(models, inputs, icam):
    """RMS projection difference inside and outside the convex hull of the
    corners camera icam saw (all views), and the share of the squared
    difference outside."""
    import cv2
    w, h = models[0].imagersize()
    centre = np.array([(w - 1) / 2.0, (h - 1) / 2.0])
    difference, _, q0, _ = mrcal.projection_diff(
        models, use_uncertainties=False, focus_center=centre,
        focus_radius=FOCUS_RADIUS_PX)
    seen = inputs["indices_frame_camintrinsics_camextrinsics"][:, 1] == icam
    corners = inputs["observations_board"][seen][..., :2].reshape(-1, 2)
    hull = cv2.convexHull(corners.astype(np.float32))
    q = q0.reshape(-1, 2)
    d = difference.ravel()
    inside = np.array([cv2.pointPolygonTest(hull, (float(x), float(y)), False)
                       >= 0 for x, y in q])
    return (float(np.sqrt(np.mean(d[inside] ** 2))),
            float(np.sqrt(np.mean(d[~inside] ** 2))),
            float(np.mean(~inside)),
            float(np.sum(d[~inside] ** 2) / np.sum(d ** 2)))


def mrcal_default(summary, images, warp=False):
    """mrcal.optimize with outlier rejection and regularisation (and the
    board deflection when warp)."""
    inputs, _ = mrcal_compare.mrcal_solve(summary, images)
    inputs["do_apply_outlier_rejection"] = True
    inputs["do_apply_regularization"] = True
    if warp:
        inputs["do_optimize_calobject_warp"] = True
        inputs["calobject_warp"] = np.zeros(2)
    stats = mrcal.optimize(**inputs)
    return inputs, stats


def intrinsics_sigma(inputs):
    """sigma of every camera's intrinsics from mrcal's solve."""
    _, x, J, _ = mrcal.optimizer_callback(**inputs)
    J = J.toarray()
    residuals = mrcal.residuals_chessboard(inputs, residuals=x).ravel()
    variance = np.var(residuals)
    cov = np.linalg.pinv(J.T @ J) * variance
    scale = np.ones(J.shape[1])
    mrcal.unpack_state(scale, **inputs)
    cov = cov * np.outer(scale, scale)
    n = mrcal.lensmodel_num_params(inputs["lensmodel"])
    sigmas = []
    for icam in range(len(inputs["intrinsics"])):
        i0 = mrcal.state_index_intrinsics(icam, **inputs)
        sigmas.append(np.sqrt(np.diag(cov)[i0:i0 + n]))
    return sigmas


def models_of(inputs):
    return [mrcal.cameramodel(optimization_inputs=inputs, icam_intrinsics=i)
            for i in range(len(inputs["intrinsics"]))]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--kincal", default="build/bin/kincal")
    parser.add_argument("--data",
                        default="../shared/data/opencv-stereo-left-right")
    parser.add_argument("--kincal-args", default="",
                        help="extra options of kincal camcal, one string")
    args = parser.parse_args()
    extra = shlex.split(args.kincal_args)
    with tempfile.TemporaryDirectory() as out_dir:
        summary = run_kincal(args.kincal, os.path.join(args.data, "left*.jpg"),
                             os.path.join(args.data, "right*.jpg"),
                             os.path.join(out_dir), extra)
        kincal_halves = []
        for h, d in enumerate(half_dirs(args.data, out_dir)):
            sub = os.path.join(out_dir, "out%d" % h)
            os.makedirs(sub)
            run_kincal(args.kincal, os.path.join(d, "left*.jpg"),
                       os.path.join(d, "right*.jpg"), sub, extra)
            kincal_halves.append(
                [mrcal.cameramodel(os.path.join(sub, "kincal-%s.cameramodel"
                                                % c["name"]))
                 for c in summary["cameras"]])

    images = summary["images"]
    warp = "--no-board-warp" not in extra
    full, full_stats = mrcal_default(summary, images, warp)
    halves = [mrcal_default(summary, images[h::2], warp)[0] for h in range(2)]
    if warp:
        print("board warp (x, y; squares): kincal %s, mrcal %s" % (
            np.round(summary["board_warp"], 5),
            np.round(full["calobject_warp"], 5)))
    outliers = int(np.sum(full["observations_board"][..., 2] <= 0))
    corners = full["observations_board"][..., 2].size
    sigmas = intrinsics_sigma(full)
    print("kincal camcal %s: %d outlier corners rejected of %d, %d views "
          "dropped" % (args.kincal_args or "(defaults)",
                       summary.get("outlier_rejection", {}).get("corners", -1),
                       sum(c["points"] for c in summary["cameras"]) +
                       summary.get("outlier_rejection", {}).get("corners", 0),
                       summary.get("outlier_rejection", {}).get("views", 0)))
    print("mrcal default: %d outlier corners of %d, RMS %.4f px"
          % (outliers, corners, full_stats["rms_reproj_error__pixels"]))
    print("\neven/odd projection difference, px (RMS within %d px of the "
          "centre / over the whole image):" % FOCUS_RADIUS_PX)
    print("  %-6s %-17s %-17s %-17s" % ("camera", "kincal (kincal)",
                                        "kincal (mrcal)", "mrcal default"))
    worst_sigma = 0.0
    consistent = True
    coverage = []
    for icam, cam in enumerate(summary["cameras"]):
        k_focus = cam.get("half_diff_focus_rms_px", float("nan"))
        k_rms = cam["half_diff_rms_px"]
        kk = diff_rms([kincal_halves[0][icam], kincal_halves[1][icam]])
        mm = diff_rms([models_of(halves[0])[icam], models_of(halves[1])[icam]])
        print("  %-6s %7.3f / %6.3f  %7.3f / %6.3f  %7.3f / %6.3f"
              % (cam["name"], k_focus, k_rms, kk[0], kk[1], mm[0], mm[1]))
        consistent &= kk[0] <= mm[0] + 5e-3 and kk[1] <= 1.05 * mm[1]
        coverage.append((cam["name"], coverage_split(
            [kincal_halves[0][icam], kincal_halves[1][icam]], full, icam),
            coverage_split([models_of(halves[0])[icam],
                            models_of(halves[1])[icam]], full, icam)))
    print("\nwhere the whole-image difference is (RMS inside / outside the "
          "convex hull of the corners the camera saw; share of the image "
          "outside; share of the squared difference outside):")
    for name, k, m in coverage:
        print("  %-6s kincal %.3f / %.3f px, %.0f %% of the image, %.1f %% "
              "of the difference; mrcal %.3f / %.3f px, %.1f %%"
              % (name, k[0], k[1], 100 * k[2], 100 * k[3], m[0], m[1],
                 100 * m[3]))
    print("\nintrinsics, kincal default against mrcal default (mrcal's "
          "sigma):")
    names = ["fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"]
    for icam, cam in enumerate(summary["cameras"]):
        ours = [cam["fx"], cam["fy"], cam["cx"], cam["cy"]] + cam["distortion"]
        theirs = full["intrinsics"][icam]
        parts = []
        for k, name in enumerate(names[:len(ours)]):
            z = (ours[k] - theirs[k]) / sigmas[icam][k]
            worst_sigma = max(worst_sigma, abs(z))
            if k < 4:
                parts.append("%s %.3f/%.3f (%+.2f s, s %.3f)" % (
                    name, ours[k], theirs[k], z, sigmas[icam][k]))
        print("  %-5s %s" % (cam["name"], "; ".join(parts)))
    print("\nlargest |kincal - mrcal| over all intrinsics: %.2f sigma"
          % worst_sigma)
    ok = consistent and worst_sigma < 3
    print("%s: kincal's halves %s mrcal's (both computed by mrcal; within "
          "0.005 px near the centre, 5 %% over the image), intrinsics within "
          "%.2f sigma (target 3)" % (
              "PASS" if ok else "FAIL",
              "agree as well as" if consistent else "agree worse than",
              worst_sigma))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
