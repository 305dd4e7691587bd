#!/usr/bin/env python3
"""Simulate a rig, calibrate it with no initial guess, and show the clouds before and after.

  PYTHONPATH=build/python /usr/bin/python3 examples/python/calibrate_rig.py [--scenario 64-horizon]

Prints the extrinsic found next to the simulator's truth. The simulated LiDARs share one clock,
which the call is told (synced_clocks=True): a 20 s drive is too short to estimate an offset
(--estimate-offset tries, and says so when the drive does not pin it). With Open3D (Debian's
python3-open3d) and a display, it opens two windows: the base's first frame (grey) with the
target's placed by no guess (identity), then by the calibration (orange). Without either, it
skips the windows. --screenshots DIR saves each window as a PNG in DIR and closes it instead of
waiting for you to (for a notebook, a report, or a machine with a virtual display:
`xvfb-run -a /usr/bin/python3 examples/python/calibrate_rig.py --screenshots shots`).
"""
import argparse
import os
import sys

import numpy as np

import ulc


def angle_deg(R):
    return np.degrees(np.arccos(np.clip((np.trace(R) - 1) / 2, -1, 1)))


# A bird's-eye view from behind and above the base, 40 m around it (Open3D's own default looks
# along an axis at the whole cloud, which for a street is a thin strip).
VIEW = dict(front=[-0.6, -0.2, 0.8], lookat=[10.0, 0.0, 0.0], up=[0.0, 0.0, 1.0], zoom=0.12)


def show(title, base_points, target_points, T, screenshot=None):
    """The base's frame and the target's moved by T, in one Open3D window; with `screenshot` (a
    PNG path) the window is saved there and closed rather than left for the user to close."""
    import open3d as o3d
    clouds = []
    for points, colour, pose in ((base_points, (0.6, 0.6, 0.6), np.eye(4)),
                                 (target_points, (1.0, 0.5, 0.0), T)):
        xyz = np.ascontiguousarray(points[:, :3], dtype=np.float64)
        cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(xyz))
        cloud.paint_uniform_color(colour)
        clouds.append(cloud.transform(pose))
    if screenshot is None:
        o3d.visualization.draw_geometries(clouds, window_name=title, **VIEW)
        return
    window = o3d.visualization.Visualizer()
    if not window.create_window(window_name=title, width=960, height=720):
        sys.exit(f"error: {screenshot}: Open3D could not open a window on this display")
    for cloud in clouds:
        window.add_geometry(cloud)
    view = window.get_view_control()
    view.set_front(VIEW["front"])
    view.set_lookat(VIEW["lookat"])
    view.set_up(VIEW["up"])
    view.set_zoom(VIEW["zoom"])
    window.poll_events()
    window.update_renderer()
    window.capture_screen_image(screenshot, do_render=True)
    window.destroy_window()
    print(f"saved {screenshot}")


def can_show():
    if not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
        print("no display: the windows are skipped")
        return False
    try:
        import open3d  # noqa: F401
    except ImportError:
        print("no open3d (apt-get install python3-open3d): the windows are skipped")
        return False
    return True


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenario", default="64-horizon", help="see ulc.scenarios()")
    p.add_argument("--seconds", type=float, default=20.0)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--estimate-offset", action="store_true",
                   help="estimate the clock offset instead of taking the clocks as synchronised")
    p.add_argument("--screenshots", metavar="DIR",
                   help="save the two windows as before.png and after.png in DIR and close them")
    args = p.parse_args()
    if args.screenshots and not os.path.isdir(args.screenshots):
        sys.exit(f"error: {args.screenshots}: no such folder (--screenshots)")

    print(f"simulating {args.seconds:g} s of {args.scenario} ...")
    drive = ulc.simulate(args.scenario, seconds=args.seconds, seed=args.seed)
    base, target = drive["lidars"][:2]
    result = ulc.calibrate(base["frames"], target["frames"], base_times=base["times"],
                           target_times=target["times"], names=[base["name"], target["name"]],
                           synced_clocks=not args.estimate_offset,
                           progress=lambda stage, f: print(f"\r{stage:24s} {100 * f:5.1f} %",
                                                           end="", flush=True))
    print()
    print(result.status, result.reason)
    truth = next(t for t in drive["truth"]
                 if (t["base"], t["target"]) == (base["name"], target["name"]))
    T, T_true = result.T_base_target, truth["T_base_target"]
    E = np.linalg.inv(T_true) @ T
    print("T_base_target =\n", np.array2string(T, precision=4, suppress_small=True))
    print(f"error against the truth: {angle_deg(E[:3, :3]):.4f} deg, "
          f"{100 * np.linalg.norm(E[:3, 3]):.2f} cm; clock offset {result.time_offset_s} s")
    if can_show():
        shots = args.screenshots
        for title, name, pose in (("before: no guess", "before.png", np.eye(4)),
                                  ("after: ULC's extrinsic", "after.png", T)):
            show(title, base["frames"][0], target["frames"][0], pose,
                 os.path.join(shots, name) if shots else None)


if __name__ == "__main__":
    try:
        main()
    except ulc.Error as e:  # the message the command line would print
        sys.exit(f"error: {e}")
