#!/usr/bin/python3
"""Plots of a dataset's calibrations from out/repeatability.csv (tiltcal_report).

extrinsic_positions.png: per-sequence position extrinsic r_b^{lb} (cm), one
panel per axis, the rig's measured value dashed and the truth (when the
sequences are simulated) dotted.
extrinsic_spread.png: spread of the extrinsic over the sequences, as bars of
the per-component standard deviation (translation cm, rotation deg, tau ms).
"""
import argparse
import csv
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def value(row, key):
    text = row.get(key, "")
    return float(text) if text not in ("", None) else None


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--csv", required=True, help="repeatability.csv")
    parser.add_argument("--out_dir", required=True)
    args = parser.parse_args()

    rows = read_rows(args.csv)
    special = {"mean", "sigma", "measured"}
    sequences = [r for r in rows if r["sequence"] not in special]
    by_name = {r["sequence"]: r for r in rows if r["sequence"] in special}
    names = [r["sequence"] for r in sequences]
    axes_keys = ["r_x_cm", "r_y_cm", "r_z_cm"]

    fig, axes = plt.subplots(1, 3, figsize=(12, 4), constrained_layout=True)
    for ax, key in zip(axes, axes_keys):
        values = [value(r, key) for r in sequences]
        ax.plot(range(len(values)), values, "o", label="estimate")
        if "measured" in by_name:
            ax.axhline(value(by_name["measured"], key), linestyle="--", color="k",
                       label="measured")
        errors = [value(r, key.replace("r_", "error_")) for r in sequences]
        if all(e is not None for e in errors) and errors:
            truths = [v - e for v, e in zip(values, errors)]
            ax.plot(range(len(truths)), truths, "x", color="tab:green", label="truth")
        ax.set_xticks(range(len(names)))
        ax.set_xticklabels(names, rotation=45, ha="right", fontsize=8)
        ax.set_title(key.replace("_cm", "") + " (cm)")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle("Position extrinsic r_b^{lb} per sequence")
    fig.savefig(os.path.join(args.out_dir, "extrinsic_positions.png"), dpi=120)
    plt.close(fig)

    sigma = by_name.get("sigma")
    labels = ["r_x cm", "r_y cm", "r_z cm", "C_1 deg", "C_2 deg", "C_3 deg", "tau ms"]
    keys = ["r_x_cm", "r_y_cm", "r_z_cm", "euler_1_deg", "euler_2_deg", "euler_3_deg",
            "time_offset_ms"]
    values = [value(sigma, k) if sigma else 0.0 for k in keys]
    fig, ax = plt.subplots(figsize=(8, 4), constrained_layout=True)
    ax.bar(labels, values, color=["tab:blue"] * 3 + ["tab:orange"] * 3 + ["tab:gray"])
    ax.set_ylabel("standard deviation over sequences")
    ax.set_title("Extrinsic spread (%d sequences)" % len(sequences))
    ax.grid(axis="y", alpha=0.3)
    fig.savefig(os.path.join(args.out_dir, "extrinsic_spread.png"), dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
