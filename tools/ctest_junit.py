#!/usr/bin/env python3
"""Runs ctest and writes its JUnit report where catkin_test_results reads it.

`catkin test` (and `make run_tests`) knows only catkin's own test kinds; gesture_formation's tests
are ctest tests. This runs ctest in the build directory with --output-junit, adds the `errors`
attribute catkin_test_results needs (ctest writes `tests`, `failures`, `skipped`, not `errors`) and
names the suite after the package, so `catkin test` reports the real counts, failures and skips.
It exits 0 whatever the tests did, as catkin's run_tests targets do (catkin_test_results reports
the failures and exits non-zero); --return-code makes it exit with ctest's status instead.

  tools/ctest_junit.py --build-dir BUILD --out RESULTS/gesture_formation/ctest.xml [--return-code] [-- CTEST_ARGS...]
"""
import argparse
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET


def convert(raw_path, out_path, suite_name):
    """Rewrites ctest's JUnit file as catkin_test_results reads it. Returns (tests, failures, skipped)."""
    tree = ET.parse(raw_path)
    root = tree.getroot()
    if root.tag != "testsuite":
        raise ValueError(f"{raw_path}: root element is <{root.tag}>, expected <testsuite>")
    cases = root.findall("testcase")
    failures = sum(1 for c in cases if c.find("failure") is not None)
    skipped = sum(1 for c in cases if c.find("skipped") is not None)
    root.set("name", suite_name)
    root.set("tests", str(len(cases)))
    root.set("failures", str(failures))
    root.set("skipped", str(skipped))
    root.set("errors", "0")
    for c in cases:
        c.set("classname", suite_name)
    os.makedirs(os.path.dirname(os.path.abspath(out_path)), exist_ok=True)
    tree.write(out_path, encoding="utf-8", xml_declaration=True)
    return len(cases), failures, skipped


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build-dir", required=True, help="the CMake build directory (where ctest runs)")
    ap.add_argument("--out", required=True, help="the JUnit file to write (catkin: CATKIN_TEST_RESULTS_DIR/<package>/ctest.xml)")
    ap.add_argument("--suite", default="gesture_formation", help="suite name in the report")
    ap.add_argument("--ctest", default="ctest", help="the ctest executable")
    ap.add_argument("--return-code", action="store_true", help="exit with ctest's status (default: 0, as catkin's run_tests)")
    ap.add_argument("ctest_args", nargs="*", help="more ctest arguments (after --)")
    a = ap.parse_args(argv)
    if not os.path.isdir(a.build_dir):
        print(f"ctest_junit.py: --build-dir {a.build_dir}: no such directory", file=sys.stderr)
        return 2
    with tempfile.TemporaryDirectory() as tmp:
        raw = os.path.join(tmp, "ctest.xml")
        rc = subprocess.call([a.ctest, "--output-junit", raw] + a.ctest_args, cwd=a.build_dir)
        if not os.path.exists(raw):
            print(f"ctest_junit.py: ctest (exit {rc}) wrote no report", file=sys.stderr)
            return rc or 1
        tests, failures, skipped = convert(raw, a.out, a.suite)
    print(f"ctest_junit.py: {tests} tests, {failures} failed, {skipped} skipped -> {a.out}")
    return rc if a.return_code else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
