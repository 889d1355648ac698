#!/usr/bin/env python3
"""Keeps the documentation describing the product as it is (docs/conventions.md, code style 14).

Checks README.md and every docs/**/*.md outside docs/results/ (dated measurements live there):
  - no date written YYYY-MM-DD;
  - no git commit hash: a lowercase hex word of 7 to 40 characters with at least one digit and
    one letter (so "deadbeef", "facade", a number or the decimals of 1.013279e-6 are not taken
    for one; a 64-digit sha256 is not a commit);
  - every relative link [text](target) / ![alt](target) names a file or directory that exists
    in the repository (anchors and http(s)/mailto links are not checked);
  - every `code span` that names a repository path (starting with src/, include/, docs/, tools/,
    test/, ... or ../) names one that exists (spans with placeholders such as <module>, * or
    DIR are not checked);
  - no path that leaves the repository: a link or a `code span` starting with ../ that resolves
    outside it, or an absolute path into a workspace (/work/..., /home/...).
Prints one line per problem (file:line: what) and exits 1 when there is any, 0 otherwise.

Usage: tools/check_docs.py [--root DIR]     (default: the repository this script is in)
       tools/check_docs.py --self-test       (runs the checks on made-up pages; exit 0 = the
                                              checks catch what they must and nothing else)
"""
import argparse
import os
import re
import sys
import tempfile

DATE = re.compile(r"(?<![0-9])(?:19|20)[0-9]{2}-(?:0[1-9]|1[0-2])-(?:0[1-9]|[12][0-9]|3[01])(?![0-9])")
HEX_WORD = re.compile(r"(?<![0-9A-Za-z.])[0-9a-f]{7,40}(?![0-9A-Za-z])")  # not the decimals of 1.013279e-6
LINK = re.compile(r"!?\[[^\]]*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
CODE_SPAN = re.compile(r"`([^`\n]+)`")
WORKSPACE_PATH = re.compile(r"(?<![0-9A-Za-z_.~-])/(?:work|home)/[0-9A-Za-z_.-]+")
EXTERNAL = ("http://", "https://", "mailto:", "ftp://")
REPO_DIRS = ("src", "include", "nodelets", "tools", "test", "config", "launch", "docs", "bench",
             "third_party_models", "msg", "srv", "fuzz", "lcm", "..")
PLACEHOLDER = re.compile(r"[<>*{}…$|]|\.\.\.|\b(?:DIR|FILE|NAME|N)\b")


def pages(root):
    """README.md and docs/**/*.md outside docs/results/, as paths relative to root."""
    found = []
    if os.path.isfile(os.path.join(root, "README.md")):
        found.append("README.md")
    docs = os.path.join(root, "docs")
    for directory, subdirs, files in os.walk(docs):
        rel_dir = os.path.relpath(directory, root)
        if rel_dir == os.path.join("docs", "results"):
            subdirs[:] = []
            continue
        subdirs.sort()
        found += [os.path.join(rel_dir, f) for f in sorted(files) if f.endswith(".md")]
    return found


def looks_like_commit(word):
    return any(c.isdigit() for c in word) and any(c in "abcdef" for c in word)


def inside(root, path):
    root = os.path.realpath(root)
    path = os.path.realpath(path)
    return path == root or path.startswith(root + os.sep)


def check_target(root, page_dir, target):
    """Problem with a relative link target, or None."""
    if target.startswith(EXTERNAL) or target.startswith("#"):
        return None
    path_part = target.split("#", 1)[0].split("?", 1)[0]
    if not path_part:
        return None
    if path_part.startswith("/"):
        return f"link to an absolute path {target!r}"
    resolved = os.path.normpath(os.path.join(root, page_dir, path_part))
    if not inside(root, resolved):
        return f"link {target!r} leaves the repository"
    if not os.path.exists(resolved):
        return f"link {target!r}: no such file in the repository"
    return None


def check_span(root, page_dir, span):
    """Problem with a `code span` that names a repository path, or None."""
    words = span.split()
    if len(words) != 1 or "/" not in words[0] or words[0].split("/")[0] not in REPO_DIRS:
        return None
    path = words[0].split("#", 1)[0].rstrip(".,;:")
    if PLACEHOLDER.search(path):
        return None
    # ../x is relative to the page; everything else to the repository's top.
    resolved = os.path.normpath(os.path.join(root, page_dir if path.startswith("../") else "", path))
    if not inside(root, resolved):
        return f"path {path!r} leaves the repository"
    if not os.path.exists(resolved):
        return f"path {path!r}: no such file or directory in the repository"
    return None


def check_page(root, rel_path):
    problems = []
    page_dir = os.path.dirname(rel_path)
    with open(os.path.join(root, rel_path), encoding="utf-8") as f:
        lines = f.read().split("\n")
    for number, line in enumerate(lines, 1):
        where = f"{rel_path}:{number}"
        for m in DATE.finditer(line):
            problems.append(f"{where}: a date {m.group(0)!r} (dated figures go to docs/results/)")
        for m in HEX_WORD.finditer(line):
            if looks_like_commit(m.group(0)):
                problems.append(f"{where}: what looks like a commit hash {m.group(0)!r} (git log keeps history)")
        for m in LINK.finditer(line):
            problem = check_target(root, page_dir, m.group(1))
            if problem:
                problems.append(f"{where}: {problem}")
        for m in CODE_SPAN.finditer(line):
            problem = check_span(root, page_dir, m.group(1))
            if problem:
                problems.append(f"{where}: {problem}")
        for m in WORKSPACE_PATH.finditer(line):
            problems.append(f"{where}: path outside the repository {m.group(0)!r}")
    return problems


def check(root):
    problems = []
    for page in pages(root):
        problems += check_page(root, page)
    return problems


def self_test():
    """The checks on made-up pages: each bad line flagged, each good line not."""
    bad = {
        "date": "Measured on 2026-12-03 on two cores.",
        "short hash": "Fixed at e2ee5c1 by the planner.",
        "hash in a file name": "Rows in `docs/data/fault_matrix_runs_cc1c243.csv`.",
        "full hash": "commit 9532ea0f36c45fe188cb514ca5a8e2ee5c1d0a1b",
        "missing link": "See [the nowhere page](nowhere.md).",
        "link out of the repo": "See [design](../../shared/DESIGN.md).",
        "path out of the repo": "Contracts: `../shared/DESIGN.md` §8.",
        "workspace path": "Read /work/shared/DESIGN.md first.",
        "missing repository path": "Code: `src/planning/nowhere.cpp`.",
        "absolute link": "![x](/tmp/x.png)",
    }
    good = [
        "The magic word deadbeef and a facade of decaf beef.",
        "271683727 bytes; 1e-14; 1.013279e-6; 0x1f2e3d4a; 2254 anchors; 10 047 of 10 050.",
        "sha256 0f3c5d1e9a7b2c4d6e8f0a1b3c5d7e9f1a3b5c7d9e1f3a5b7c9d1e3f5a7b9c1d of the model.",
        "See [architecture](architecture.md), ![pic](images/a.png) and [web](https://example.org/x).",
        "Seeds 1..20, 2026 samples, 12-03 ranges, /opt/gesture_formation/venv and /tmp/h3.",
        "[section](#rules) and [results](results/demo.md#seed-1).",
        "Code: `docs/architecture.md`, `test/unit/<module>/test_*.cpp`, `src/gfctl/cmd_*.cpp`, `docs/` and `gfctl simulate --out DIR`.",
    ]
    with tempfile.TemporaryDirectory() as root:
        os.makedirs(os.path.join(root, "docs", "images"))
        os.makedirs(os.path.join(root, "docs", "results"))
        for name in ("docs/architecture.md", "docs/images/a.png", "docs/results/demo.md"):
            open(os.path.join(root, name), "w").close()
        failures = 0
        for what, line in bad.items():
            with open(os.path.join(root, "docs", "page.md"), "w", encoding="utf-8") as f:
                f.write("# page\n" + line + "\n")
            found = check(root)
            if not found:
                print(f"FAIL: not flagged ({what}): {line}")
                failures += 1
            else:
                print(f"ok: flagged ({what}): {found[0]}")
        with open(os.path.join(root, "docs", "page.md"), "w", encoding="utf-8") as f:
            f.write("# page\n" + "\n".join(good) + "\n")
        with open(os.path.join(root, "docs", "results", "demo.md"), "w", encoding="utf-8") as f:
            f.write("Measured 2026-12-03 at e2ee5c1.\n")  # allowed in docs/results/
        found = check(root)
        for problem in found:
            print(f"FAIL: false positive: {problem}")
        failures += len(found)
        if not found:
            print(f"ok: {len(good)} good lines and a dated docs/results/ page not flagged")
    return 1 if failures else 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--root", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    parser.add_argument("--self-test", action="store_true")
    args = parser.parse_args()
    if args.self_test:
        return self_test()
    if not os.path.isdir(os.path.join(args.root, "docs")):
        print(f"check_docs: --root {args.root!r} has no docs/ directory", file=sys.stderr)
        return 2
    problems = check(args.root)
    for problem in problems:
        print(problem)
    checked = len(pages(args.root))
    print(f"check_docs: {checked} pages, {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
