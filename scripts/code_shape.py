#!/usr/bin/env python3
"""The shape of the C++ tree: which folder includes which, and the longest functions.

    python3 scripts/code_shape.py            # folder dependencies and the 15 longest functions
    python3 scripts/code_shape.py --check    # exit 1 when a folder includes one above it

The layers point one way (README, "Layout"): a folder may include only itself and the folders
listed before it in LAYERS. tests/, bench/ and the add-on's module may include everything.
"""
import argparse
import collections
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
# Each folder with the folders it may include (besides itself).
LAYERS = {
    "core": [],
    "scene": ["core"],
    "shaders": ["core", "scene"],
    "render": ["core", "scene", "shaders"],
    "integrators": ["core", "scene", "shaders", "render"],
    "reconstruct": ["core"],
    "testing": ["core", "scene", "shaders", "render", "integrators", "reconstruct"],
}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
SOURCES = ("*.h", "*.cpp")


def sources(folder):
    for pattern in SOURCES:
        yield from sorted((ROOT / folder).rglob(pattern))


def folder_dependencies():
    """{folder: {included folder: number of includes}} over the layered folders."""
    deps = {}
    for folder in LAYERS:
        counts = collections.Counter()
        for path in sources(folder):
            for inc in INCLUDE.findall(path.read_text(errors="replace")):
                top = inc.split("/", 1)[0]
                if "/" in inc and top != folder:
                    counts[top] += 1
        deps[folder] = counts
    return deps


def violations(deps):
    return [(f, d) for f, counts in deps.items() for d in counts if d not in LAYERS[f]]


# A function definition: a line at namespace or class scope whose signature ends in "{".
SIGNATURE = re.compile(r"^(?:\s{0,2})(?!if\b|for\b|while\b|switch\b|namespace\b|struct\b|class\b|"
                       r"enum\b|union\b|extern\b|return\b|else\b|do\b)[^;#/]*\)[^;]*\{\s*$")


def function_name(lines, i):
    """The name in the declaration that ends at line i (it may span several lines)."""
    start = i
    while start > 0 and start > i - 8 and not re.match(r"^\s{0,2}[\w~]", lines[start]):
        start -= 1
    names = re.findall(r"([~\w:]+)\s*\(", " ".join(lines[start:i + 1]))
    names = [n for n in names if n not in ("if", "for", "while", "switch", "return", "sizeof")]
    return names[0] if names else lines[i].strip()


def functions(path):
    """(lines, name, first line) of each function body in a file, by brace matching."""
    lines = path.read_text(errors="replace").splitlines()
    found = []
    i = 0
    while i < len(lines):
        if SIGNATURE.match(lines[i]):
            depth, j = 0, i
            while j < len(lines):
                depth += lines[j].count("{") - lines[j].count("}")
                if depth <= 0 and j > i or (depth == 0 and "}" in lines[j]):
                    break
                j += 1
            found.append((j - i + 1, function_name(lines, i), i + 1))
            i = j + 1
        else:
            i += 1
    return found


def longest(count):
    rows = []
    for folder in list(LAYERS) + ["blender_addon/module"]:
        for path in sources(folder):
            for n, name, line in functions(path):
                rows.append((n, f"{path.relative_to(ROOT)}:{line}", name))
    return sorted(rows, reverse=True)[:count]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="fail on an upward include")
    parser.add_argument("--longest", type=int, default=15, help="how many functions to list")
    args = parser.parse_args()
    deps = folder_dependencies()
    bad = violations(deps)
    if args.check:
        for f, d in bad:
            files = [str(p.relative_to(ROOT)) for p in sources(f)
                     if re.search(rf'#\s*include\s+"{d}/', p.read_text(errors="replace"))]
            print(f"code_shape: {f}/ includes {d}/, which is not below it: {', '.join(files)}")
        print(f"code_shape: {len(bad)} upward include(s) across {len(LAYERS)} folders")
        return 1 if bad else 0
    print("folder -> folders it includes (number of #include lines)")
    for folder, counts in deps.items():
        listed = ", ".join(f"{d} ({n})" for d, n in sorted(counts.items())) or "-"
        flag = "  <- NOT ALLOWED" if any(f == folder for f, _ in bad) else ""
        print(f"  {folder:12s} -> {listed}{flag}")
    print(f"\nthe {args.longest} longest functions (lines, place, name)")
    for n, where, name in longest(args.longest):
        print(f"  {n:5d}  {where:55s} {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
