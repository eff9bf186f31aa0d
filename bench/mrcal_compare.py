#!/usr/bin/python3
"""kincal camcal against mrcal on OpenCV's stereo chessboard pairs.

Runs where mrcal is installed (Debian: apt-get install mrcal python3-mrcal;
the script needs the system python3 that has the mrcal module, and cv2).

1. Projection uncertainty. `kincal camcal --loss none --reject-sigma 0
   --no-board-warp --regularize-lens 0` (plain least squares) reports mrcal's projection
   uncertainty (worst-direction 1-sigma, points at
   infinity) at the image centre and corners. The same corners (OpenCV's
   findChessboardCorners + cornerSubPix 11x11, as kincal detects them) are
   solved by mrcal.optimize without regularisation or outlier rejection,
   seeded by kincal's solution, and mrcal.projection_uncertainty(atinfinity)
   is evaluated at the same pixels. Printed side by side with the ratio.
2. .cameramodel round trip. mrcal writes PINHOLE / OPENCV5 / OPENCV8 models;
   `kincal import cameramodel` turns them into rig.yaml; the projection of
   3D points with rig.yaml's numbers (OpenCV's equations, cv2.projectPoints)
   is compared with mrcal.project on the model. And back: the models that
   `kincal camcal --out-cameramodel` wrote are read by mrcal and projected
   against rig.yaml. Both must agree to 1e-9 px.

Usage (from the worktree root, after building):
  /usr/bin/python3 bench/mrcal_compare.py [--kincal build/bin/kincal]
      [--data ../shared/data/opencv-stereo-left-right] [--distance SQUARES]
Exit 1 when a round trip differs by more than 1e-9 px or an uncertainty
differs by more than 15 %.
"""

import argparse
import glob
import json
import os
import subprocess
import sys
import tempfile

import cv2
import mrcal
import numpy as np

BOARD_COLS, BOARD_ROWS = 9, 6


def run_kincal(kincal, data, out_dir, distance):
    cmd = [kincal, "camcal", "--uncertainty-distance", str(distance),
           "--left", os.path.join(data, "left*.jpg"),
           "--right", os.path.join(data, "right*.jpg"),
           "--target", "chessboard:9x6:1", "--loss", "none",
           "--reject-sigma", "0", "--no-board-warp", "--regularize-lens", "0",
           "--out", os.path.join(out_dir, "rig.yaml"),
           "--out-cameramodel", os.path.join(out_dir, "kincal"), "--json"]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def detect(path):
    gray = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
    ok, corners = cv2.findChessboardCorners(
        gray, (BOARD_COLS, BOARD_ROWS),
        cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE)
    if not ok:
        return None, gray.shape
    corners = cv2.cornerSubPix(
        gray, corners, (11, 11), (-1, -1),
        (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 30, 0.01))
    return corners.reshape(BOARD_ROWS, BOARD_COLS, 2), gray.shape


def pose_rt(R, t):
    return np.concatenate([cv2.Rodrigues(np.asarray(R, float))[0].ravel(),
                           np.asarray(t, float)])


def camera_arrays(cam):
    K = np.array([[cam["fx"], 0, cam["cx"]], [0, cam["fy"], cam["cy"]],
                  [0, 0, 1]])
    return K, np.array(cam["distortion"], float)


def mrcal_solve(summary, images):
    """mrcal's least squares on the corners kincal detects, seeded by kincal."""
    cams = summary["cameras"]
    board = mrcal.ref_calibration_object(BOARD_COLS, BOARD_ROWS, 1.0)
    observations, indices, frames = [], [], []
    for row in images:
        found = [detect(row[c["name"]]) for c in cams]
        seen = [i for i, (corners, _) in enumerate(found) if corners is not None]
        if not seen:
            continue
        # Seed the frame pose (rig_from_target) by PnP in the first camera
        # that sees it.
        i0 = seen[0]
        K, dist = camera_arrays(cams[i0])
        ok, rvec, tvec = cv2.solvePnP(board.reshape(-1, 3),
                                      found[i0][0].reshape(-1, 2), K, dist)
        R = cv2.Rodrigues(rvec)[0]
        cam_from_rig = cams[i0]["cam_from_rig"]
        Rc = np.array(cam_from_rig["R"]).reshape(3, 3)
        tc = np.array(cam_from_rig["t"])
        frames.append(pose_rt(Rc.T @ R, Rc.T @ (tvec.ravel() - tc)))
        for i in seen:
            obs = np.ones((BOARD_ROWS, BOARD_COLS, 3))
            obs[..., :2] = found[i][0]
            observations.append(obs)
            indices.append((len(frames) - 1, i, i - 1))
    intrinsics = np.array([[c["fx"], c["fy"], c["cx"], c["cy"]] + c["distortion"]
                           for c in cams])
    extrinsics = np.array([pose_rt(np.array(c["cam_from_rig"]["R"]).reshape(3, 3),
                                   c["cam_from_rig"]["t"]) for c in cams[1:]])
    inputs = dict(
        intrinsics=intrinsics,
        observations_point=None,
        indices_point_camintrinsics_camextrinsics=None,
        extrinsics_rt_fromref=extrinsics,
        frames_rt_toref=np.array(frames),
        points=None,
        observations_board=np.array(observations),
        indices_frame_camintrinsics_camextrinsics=np.array(indices, dtype=np.int32),
        lensmodel="LENSMODEL_OPENCV%d" % len(cams[0]["distortion"]),
        imagersizes=np.array([[c["width"], c["height"]] for c in cams],
                             dtype=np.int32),
        calibration_object_spacing=1.0,
        do_optimize_intrinsics_core=True,
        do_optimize_intrinsics_distortions=True,
        do_optimize_extrinsics=True,
        do_optimize_frames=True,
        do_optimize_calobject_warp=False,
        calobject_warp=None,
        do_apply_outlier_rejection=False,
        do_apply_regularization=False,
        verbose=False)
    stats = mrcal.optimize(**inputs)
    return inputs, stats


def compare_uncertainty(summary, distance):
    inputs, stats = mrcal_solve(summary, summary["images"])
    residuals = mrcal.residuals_chessboard(inputs, residuals=stats["x"]).ravel()
    n_meas = residuals.size
    dof_factor = summary["residual_sigma_px"] / np.std(residuals)
    print("mrcal least squares: %d corners, RMS %.4f px per coordinate, "
          "observed_pixel_uncertainty (np.std) %.4f px; kincal's sigma "
          "sqrt(sum r^2 / (m - n)) is %.4f times that (the degrees-of-freedom "
          "correction)" % (n_meas // 2, stats["rms_reproj_error__pixels"],
                           np.std(residuals), dof_factor))
    worst = worst_corrected = 0.0
    for icam, cam in enumerate(summary["cameras"]):
        model = mrcal.cameramodel(optimization_inputs=inputs,
                                  icam_intrinsics=icam)
        lensmodel, intr = model.intrinsics()
        print("\n%s: fx fy cx cy kincal %.4f %.4f %.4f %.4f | mrcal %.4f %.4f "
              "%.4f %.4f" % (cam["name"], cam["fx"], cam["fy"], cam["cx"],
                             cam["cy"], *intr[:4]))
        u = cam["projection_uncertainty"]
        samples = [("centre", u["centre"])] + [
            ("corner %d" % k, c) for k, c in enumerate(u["corners"])]
        print("  %-9s %-18s %10s %10s %7s" %
              ("where", "pixel", "kincal", "mrcal", "ratio"))
        for name, s in samples:
            q = np.array(s["pixel"], float)
            v = mrcal.unproject(q, lensmodel, intr, normalize=True)
            if distance > 0:
                v = v * distance
            sigma = float(mrcal.projection_uncertainty(
                v, model=model, atinfinity=distance == 0,
                what="worstdirection-stdev"))
            ratio = s["sigma_px"] / sigma
            worst = max(worst, abs(ratio - 1))
            worst_corrected = max(worst_corrected, abs(ratio / dof_factor - 1))
            print("  %-9s (%7.1f, %7.1f) %10.4f %10.4f %7.4f" %
                  (name, q[0], q[1], s["sigma_px"], sigma, ratio))
    print("\nlargest relative difference of the uncertainty: %.1f %% (after "
          "removing the degrees-of-freedom factor %.4f: %.2g %%)" %
          (100 * worst, dof_factor, 100 * worst_corrected))
    return worst


def project_opencv(rig_cam, points):
    K, dist = camera_arrays(rig_cam)
    px, _ = cv2.projectPoints(points, np.zeros(3), np.zeros(3), K,
                              dist if dist.size else None)
    return px.reshape(-1, 2)


def read_rig(path):
    """The numbers of rig.yaml (the subset the comparison needs)."""
    import yaml
    with open(path) as f:
        return yaml.safe_load(f)["cameras"]


def test_points():
    rng = np.random.default_rng(1)
    p = rng.uniform([-0.6, -0.45, 1.0], [0.6, 0.45, 1.0], (200, 3))
    return p * rng.uniform(0.5, 20, (200, 1))


def compare_round_trip(kincal, out_dir, summary):
    worst = 0.0
    points = test_points()
    examples = {
        "LENSMODEL_PINHOLE": [1800.5, 1801.25, 639.5, 511.75],
        "LENSMODEL_OPENCV5": [535.9, 536.2, 342.3, 235.5, -0.265, -0.046,
                              0.0018, -0.00027, 0.25],
        "LENSMODEL_OPENCV8": [1800.5, 1801.25, 639.5, 511.75, -0.2, 0.1,
                              0.001, -0.002, 0.01, 0.02, -0.01, 0.003],
    }
    print("\n.cameramodel round trip (max |projection difference| over 200 "
          "points, px):")
    for name, intr in examples.items():
        m = mrcal.cameramodel(intrinsics=(name, np.array(intr, float)),
                              imagersize=(1280, 1024),
                              extrinsics_rt_fromref=np.array(
                                  [0.01, 0.02, -0.03, -0.12, 0.0005, 0.001]))
        path = os.path.join(out_dir, name + ".cameramodel")
        m.write(path)
        rig_path = os.path.join(out_dir, name + ".yaml")
        subprocess.run([kincal, "import", "cameramodel", "--camera",
                        "cam=" + path, "--unit-mm", "1000", "--out", rig_path],
                       check=True, capture_output=True)
        back = mrcal.cameramodel(path)
        d = np.abs(project_opencv(read_rig(rig_path)[0], points) -
                   mrcal.project(points, *back.intrinsics())).max()
        worst = max(worst, d)
        print("  mrcal -> kincal  %-18s %.2e" % (name, d))
    rig = read_rig(os.path.join(out_dir, "rig.yaml"))
    for cam in rig:
        path = os.path.join(out_dir, "kincal-%s.cameramodel" % cam["name"])
        m = mrcal.cameramodel(path)
        d = np.abs(project_opencv(cam, points) -
                   mrcal.project(points, *m.intrinsics())).max()
        # Extrinsics: mrcal's rt_cam_ref against rig.yaml's cam_from_rig.
        R = np.array(cam["cam_from_rig"]["R"]).reshape(3, 3)
        t = np.array(cam["cam_from_rig"]["t"])
        ext = m.extrinsics_rt_fromref()
        de = max(np.abs(cv2.Rodrigues(ext[:3])[0] - R).max(),
                 np.abs(ext[3:] - t).max())
        worst = max(worst, d)
        print("  kincal -> mrcal  %-18s %.2e (extrinsics %.1e)" %
              (cam["name"] + " " + m.intrinsics()[0][10:], d, de))
    return worst


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--kincal", default="build/bin/kincal")
    parser.add_argument("--data", default="../shared/data/opencv-stereo-left-right")
    parser.add_argument("--distance", type=float, default=0,
                        help="distance of the points, squares (0 = infinity)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as out_dir:
        summary = run_kincal(args.kincal, args.data, out_dir, args.distance)
        print("kincal camcal --loss none --reject-sigma 0 --no-board-warp "
              "--regularize-lens 0: "
              "RMS %.4f px, residual sigma %.4f px (per coordinate, "
              "dof-corrected)" %
              (summary["rms_px"], summary["residual_sigma_px"]))
        print("points at %s" % ("infinity" if args.distance == 0 else
                                "%g squares" % args.distance))
        uncertainty = compare_uncertainty(summary, args.distance)
        round_trip = compare_round_trip(args.kincal, out_dir, summary)
    ok = uncertainty <= 0.15 and round_trip <= 1e-9
    print("\n%s: uncertainty within %.1f %% (target 15 %%), round trip %.1e px "
          "(target 1e-9)" % ("PASS" if ok else "FAIL", 100 * uncertainty,
                             round_trip))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
