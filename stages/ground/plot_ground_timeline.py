#!/usr/bin/python3
"""Ground-plane timeline of one sequence from `tiltcal_inspect csv ground.binpb`.

Top: tilt of the ground normal n_l from the LiDAR z axis (deg) per scan.
Bottom: LiDAR height d_l above the ground (m). Rejected scans are marked with
red crosses at their fitted values (or at the axis bottom when the fit failed).
"""
import argparse
import csv
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--csv", required=True, help="ground.csv")
    parser.add_argument("--out", required=True, help="PNG to write")
    parser.add_argument("--title", default="")
    args = parser.parse_args()

    with open(args.csv, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        t0 = 0
    else:
        t0 = int(rows[0]["stamp_ns"])
    good_t, good_tilt, good_h, bad_t, bad_tilt, bad_h = [], [], [], [], [], []
    for row in rows:
        t = (int(row["stamp_ns"]) - t0) * 1e-9
        nz = float(row["normal_in_lidar.z"])
        tilt = math.degrees(math.acos(max(-1.0, min(1.0, nz)))) if nz != 0 else float("nan")
        height = float(row["height_m"])
        if row["valid"] == "1":
            good_t.append(t), good_tilt.append(tilt), good_h.append(height)
        else:
            bad_t.append(t), bad_tilt.append(tilt), bad_h.append(height)

    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(10, 6), sharex=True, constrained_layout=True)
    ax1.plot(good_t, good_tilt, ".", markersize=3, label="valid")
    ax1.plot(bad_t, bad_tilt, "x", color="red", label="rejected (%d)" % len(bad_t))
    ax1.set_ylabel("tilt of n_l from z (deg)")
    ax1.legend(fontsize=8)
    ax1.grid(alpha=0.3)
    ax2.plot(good_t, good_h, ".", markersize=3)
    ax2.plot(bad_t, bad_h, "x", color="red")
    ax2.set_ylabel("height d_l (m)")
    ax2.set_xlabel("time since first scan (s)")
    ax2.grid(alpha=0.3)
    fig.suptitle("Ground planes %s (%d scans)" % (args.title, len(rows)))
    fig.savefig(args.out, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
