#!/usr/bin/python3
"""The layering of stages/calibrate (docs/design.md, "The calibrator's wings").

Usage: wing_layering_test.py SOURCE_DIR [BUILD_DIR DATASET_CALIBRATION_BINARY]

The calibrator is split into wings, lowest first:
  residuals < problem < report < odometry < init < the stage top
(the top: the files directly in stages/calibrate/). Checked:
  (a) every #include "stages/calibrate/..." in stages/calibrate/** names an
      existing file of the same wing or a lower one;
  (b) the wings' include graph has no cycle;
  (c) PCL and nanoflann are included by odometry/ only, and a header of
      odometry/ that includes them is included from odometry/ only;
  (d) with BUILD_DIR and the binary: tiltcal_dataset_calibration links neither
      PCL nor the odometry, init or top libraries of the calibrator (its
      link line in BUILD_DIR/build.ninja and ldd).
Exit status 0 when all hold; otherwise each violation is printed.
"""

import os
import re
import subprocess
import sys

WINGS = ["residuals", "problem", "report", "odometry", "init", ""]
RANK = {wing: rank for rank, wing in enumerate(WINGS)}
STAGE = "stages/calibrate"
# Made by tiltcal_add_stage in the build tree (the stage top's params).
GENERATED = {"stages/calibrate/default_params_text.h"}
INCLUDE = re.compile(r'^\s*#\s*include\s+"(stages/calibrate/[^"]+)"', re.M)
THIRD_PARTY = re.compile(r"^\s*#\s*include\s+<(pcl/|nanoflann)", re.M)
# Libraries tiltcal_dataset_calibration must not link (the report wing and
# what is below it are all it needs of the calibrator).
FORBIDDEN_LINKS = ["pcl", "nanoflann", "tiltcal_calibrate_odometry", "tiltcal_calibrate_init",
                   "tiltcal_calibrate_lib"]


def wing_of(path):
    """The wing of a path relative to the source tree ("" for the top)."""
    parts = path[len(STAGE) + 1:].split("/")
    return parts[0] if len(parts) > 1 and parts[0] in RANK else ""


def name(wing):
    return wing if wing else "top"


def sources(source_dir):
    for root, _, files in os.walk(os.path.join(source_dir, STAGE)):
        for f in sorted(files):
            if f.endswith((".h", ".cc")):
                full = os.path.join(root, f)
                yield os.path.relpath(full, source_dir), full


def check_includes(source_dir, errors):
    """(a) and (c); returns the wing graph {wing: {included wing}}."""
    graph = {wing: set() for wing in WINGS}
    third_party_headers = set()
    includes = {}
    for rel, full in sources(source_dir):
        with open(full, encoding="utf-8") as f:
            text = f.read()
        includes[rel] = INCLUDE.findall(text)
        if THIRD_PARTY.search(text):
            if wing_of(rel) != "odometry":
                errors.append(f"{rel}: includes PCL or nanoflann outside odometry/")
            elif rel.endswith(".h"):
                third_party_headers.add(rel)
    for rel, targets in includes.items():
        wing = wing_of(rel)
        for target in targets:
            if target not in GENERATED and not os.path.isfile(os.path.join(source_dir, target)):
                errors.append(f"{rel}: includes {target}, which does not exist")
                continue
            target_wing = wing_of(target)
            if target_wing != wing:
                graph[wing].add(target_wing)
            if RANK[target_wing] > RANK[wing]:
                errors.append(f"{rel} ({name(wing)}) includes {target} ({name(target_wing)}), "
                              f"a higher wing")
            if target in third_party_headers and wing != "odometry":
                errors.append(f"{rel} includes {target}, which brings PCL or nanoflann out of "
                              f"odometry/")
    return graph


def find_cycle(graph):
    """(b): a cycle of wings as a list, or None."""
    state = {}

    def visit(wing, path):
        state[wing] = "open"
        for nxt in sorted(graph[wing]):
            if state.get(nxt) == "open":
                return path[path.index(nxt):] + [nxt]
            if nxt not in state:
                cycle = visit(nxt, path + [nxt])
                if cycle:
                    return cycle
        state[wing] = "done"
        return None

    for wing in WINGS:
        if wing not in state:
            cycle = visit(wing, [wing])
            if cycle:
                return cycle
    return None


def check_dataset_calibration(build_dir, binary, errors):
    """(d): the link line in build.ninja and the shared libraries."""
    with open(os.path.join(build_dir, "build.ninja"), encoding="utf-8") as f:
        ninja = f.read()
    target = os.path.relpath(binary, build_dir)
    block = re.search(r"^build " + re.escape(target) + r":.*?(?=^build |\Z)", ninja, re.M | re.S)
    if block is None:
        errors.append(f"build.ninja: no link rule for {target}")
    else:
        libs = re.search(r"^\s*LINK_LIBRARIES = (.*)$", block.group(0), re.M)
        line = libs.group(1) if libs else ""
        for lib in FORBIDDEN_LINKS:
            if lib in line:
                errors.append(f"{target} links {lib}")
    ldd = subprocess.run(["ldd", binary], capture_output=True, text=True, check=False)
    if ldd.returncode != 0:
        errors.append(f"ldd {binary} failed: {ldd.stderr.strip()}")
    for lib in ldd.stdout.splitlines():
        if "libpcl" in lib:
            errors.append(f"{target} loads {lib.split()[0]}")


def main(argv):
    if len(argv) not in (2, 4):
        print(__doc__)
        return 2
    errors = []
    graph = check_includes(argv[1], errors)
    cycle = find_cycle(graph)
    if cycle:
        errors.append("include cycle between wings: " + " -> ".join(name(w) for w in cycle))
    if len(argv) == 4:
        check_dataset_calibration(argv[2], argv[3], errors)
    for wing in WINGS:
        print(f"{name(wing)} includes: {', '.join(name(w) for w in sorted(graph[wing], key=RANK.get)) or '-'}")
    for e in errors:
        print("LAYERING:", e)
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
