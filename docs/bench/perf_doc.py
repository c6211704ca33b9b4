#!/usr/bin/env python3
"""Writes the tables of docs/performance.md that come from the bench outputs
committed next to this script, so the page carries the numbers the bench
printed rather than numbers pasted by hand; the prose around them stays
hand-written. ctest's docs.performance (tests/arch) runs it with --check.

A generated table sits between two comments, which this script writes too:
    <!-- generated: NAME from SOURCE[, SOURCE...] by docs/bench/perf_doc.py; do not edit -->
    ...
    <!-- end generated -->
Every other table on the page must follow a comment that says where it comes
from (<!-- hand-copied: ... --> with the command that gave it, or
<!-- hand-written: ... --> for a table that is not a measurement), so a table
pasted later without one fails the check.

Usage: perf_doc.py [--check] [REPO_ROOT]   (REPO_ROOT: default this file's ../..)
  without --check: rewrites the generated sections of docs/performance.md
  --check: changes nothing; exit 1, naming the section and its first
           differing line, if the page is not what this script writes
"""

import json
import math
import sys
from decimal import ROUND_HALF_UP, Decimal
from pathlib import Path

PAGE = "docs/performance.md"
SCRIPT = "docs/bench/perf_doc.py"
END = "<!-- end generated -->"


# --- Reading a skyshell-bench run (renderer/bench/src/report.cpp) ----------

def number(text):
    """A cell of results.md as a float: '5.58x' -> 5.58, '∞' -> inf, 'n/a' or '' -> None."""
    text = text.strip().rstrip("x")
    if text in ("", "n/a"):
        return None
    if text == "∞":
        return math.inf
    return float(text)


def cases_from_markdown(path):
    """The cases of a results.md: one dict per table row, per '## WxH' section."""
    cases, size = [], None
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("## "):
            head = line[3:].strip()
            size = head if "x" in head and head.replace("x", "").isdigit() else None
            continue
        if size is None or not line.startswith("| ") or line.startswith("| scene |"):
            continue
        cells = [c.strip() for c in line.split("|")[1:14]]
        if len(cells) < 13:
            continue
        scene, configuration = cells[0], cells[1]
        cases.append({
            "size": size,
            "scene": scene.removesuffix(" (path)"),
            "path": scene.endswith(" (path)"),
            # a configuration drawn at another size carries it: "half-res (160x90)"
            "configuration": configuration.split(" (")[0],
            "wall_ms": number(cells[2].split(" [")[0]),
            "speedup": number(cells[6]),
            "ssim": number(cells[9]),
        })
    return cases


def cases_from_json(path):
    """The cases of a results.json (full precision; same fields as cases_from_markdown)."""
    report = json.loads(path.read_text(encoding="utf-8"))
    return [{
        "size": f"{c['width']}x{c['height']}",
        "scene": c["scene"],
        "path": c["path"],
        "configuration": c["configuration"],
        "wall_ms": c["wall_ms"]["median"],
        "speedup": c["speedup_vs_reference"],
        "ssim": c["error"]["ssim"],
    } for c in report["cases"]]


def refine_speedups(cases):
    """results.md rounds the speed-up to 0.01 (364.94x) and the medians it is
    the ratio of to 0.01 ms (1632.86 / 4.47): the column is the finer figure
    for large speed-ups, the ratio for small ones. Each case's speed-up becomes
    the ratio of the medians held within the column's rounding interval, which
    is as close to the bench's own value as the file allows."""
    reference = {(c["size"], c["scene"]): c["wall_ms"] for c in cases if c["configuration"] == "reference"}
    for c in cases:
        ref = reference.get((c["size"], c["scene"]))
        if c["speedup"] is None or not ref or not c["wall_ms"]:
            continue
        c["speedup"] = min(max(ref / c["wall_ms"], c["speedup"] - 0.005), c["speedup"] + 0.005)
    return cases


def read_cases(root, source):
    """The cases of a results.md or a results.json."""
    path = root / source
    if path.suffix == ".json":
        return cases_from_json(path)
    return refine_speedups(cases_from_markdown(path))


# --- Formatting a range over scenes ----------------------------------------

def fixed(value, digits):
    """value with digits decimals, halves rounded up (7168.50 -> 7169)."""
    step = Decimal(1).scaleb(-digits)
    return str(Decimal(value).quantize(step, rounding=ROUND_HALF_UP))


def spread(values):
    values = [v for v in values if v is not None and math.isfinite(v)]
    return (min(values), max(values)) if values else None


def joined(low, high, unit=""):
    return f"{low}{unit}" if low == high else f"{low}-{high}{unit}"


def speedup_range(values):
    r = spread(values)
    if r is None:
        return "n/a"
    if r == (1.0, 1.0):
        return "1x"  # reference against itself
    return joined(fixed(r[0], 1), fixed(r[1], 1), "x")


def ssim_range(values):
    r = spread(values)
    if r is None:
        return "n/a"
    if r == (1.0, 1.0):
        return "1"
    # Near 1 the fourth decimal is the one that differs: the high end keeps it,
    # and so does the low end when three decimals would round it to 1.
    low = fixed(r[0], 3) if r[0] < 0.9995 else fixed(r[0], 4)
    return joined(low, fixed(r[1], 4))


def wall_range(values):
    r = spread(values)
    if r is None:
        return "n/a"
    digits = 1 if r[0] < 20 else 0  # tenths below 20 ms, whole ms above
    return joined(fixed(r[0], digits), fixed(r[1], digits))


# --- The generated tables ---------------------------------------------------

def presets_stills(root, sources):
    """Per configuration, over the still scenes (not the camera paths): the
    speed-up against reference, SSIM and median wall ms, each as min-max, one
    group of columns per resolution of each source."""
    groups = []  # (size, cases)
    for source in sources:
        cases = [c for c in read_cases(root, source) if not c["path"]]
        for size in dict.fromkeys(c["size"] for c in cases):
            groups.append((size, [c for c in cases if c["size"] == size]))
    configurations = list(dict.fromkeys(c["configuration"] for _, cases in groups for c in cases))
    head = "| configuration |" + "".join(f" {size} speed-up | SSIM | wall ms |" for size, _ in groups)
    lines = [head, "|---" * (1 + 3 * len(groups)) + "|"]
    for name in configurations:
        row = f"| `{name}` |"
        for _, cases in groups:
            mine = [c for c in cases if c["configuration"] == name]
            if not mine:
                row += " | | |"
                continue
            row += (f" {speedup_range(c['speedup'] for c in mine)} |"
                    f" {ssim_range(c['ssim'] for c in mine)} |"
                    f" {wall_range(c['wall_ms'] for c in mine)} |")
        lines.append(row)
    return lines


# name -> (how to write it, the committed bench outputs it reads)
SECTIONS = {
    "presets-stills": (presets_stills, ["docs/bench/skyshell-bench-320x180.md",
                                        "docs/bench/skyshell-bench-640x360.md"]),
}


def begin_marker(name, sources):
    return f"<!-- generated: {name} from {', '.join(sources)} by {SCRIPT}; do not edit -->"


# --- The page -----------------------------------------------------------------

def find_sections(lines):
    """name -> (index of its begin marker, index of its end marker)."""
    found = {}
    for i, line in enumerate(lines):
        if not line.startswith("<!-- generated: "):
            continue
        name = line[len("<!-- generated: "):].split(" ")[0]
        end = next((j for j in range(i + 1, len(lines)) if lines[j] == END), None)
        if end is None:
            raise SystemExit(f"FAIL: {PAGE}:{i + 1}: section {name}: no '{END}' after it")
        found[name] = (i, end)
    return found


def unmarked_tables(lines, sections):
    """Line numbers (1-based) of tables neither generated nor said to be hand-made."""
    inside = set()
    for begin, end in sections.values():
        inside.update(range(begin, end + 1))
    problems, fence = [], False
    for i, line in enumerate(lines):
        if line.startswith("```"):
            fence = not fence
        if fence or not line.startswith("|") or (i > 0 and lines[i - 1].startswith("|")) or i in inside:
            continue
        before = next((lines[j] for j in range(i - 1, -1, -1) if lines[j].strip()), "")
        if not before.startswith(("<!-- hand-copied", "<!-- hand-written")):
            problems.append(i + 1)
    return problems


def main(argv):
    check = "--check" in argv
    rest = [a for a in argv if a != "--check"]
    root = Path(rest[0]) if rest else Path(__file__).resolve().parents[2]
    page = root / PAGE
    lines = page.read_text(encoding="utf-8").splitlines()
    sections = find_sections(lines)
    failures, differs = 0, False

    for name in SECTIONS:
        if name not in sections:
            print(f"FAIL: {PAGE}: section {name}: no '{begin_marker(name, SECTIONS[name][1])}' on the page")
            failures += 1
    for name in sections:
        if name not in SECTIONS:
            print(f"FAIL: {PAGE}:{sections[name][0] + 1}: section {name}: {SCRIPT} does not know it")
            failures += 1

    for n in unmarked_tables(lines, sections):
        print(f"FAIL: {PAGE}:{n}: a table neither generated nor marked '<!-- hand-copied: COMMAND -->' "
              f"(or '<!-- hand-written: ... -->' if it is not a measurement)")
        failures += 1

    # Rewrite from the last section up, so earlier indices stay valid.
    for name, (begin, end) in sorted(sections.items(), key=lambda s: -s[1][0]):
        if name not in SECTIONS:
            continue
        write, sources = SECTIONS[name]
        missing = [s for s in sources if not (root / s).is_file()]
        if missing:
            print(f"FAIL: {PAGE}:{begin + 1}: section {name}: no {', '.join(missing)}")
            failures += 1
            continue
        wanted = [begin_marker(name, sources)] + write(root, sources) + [END]
        have = lines[begin:end + 1]
        if have == wanted:
            continue
        differs = True
        if check:
            k = next(k for k in range(max(len(have), len(wanted)))
                     if k >= len(have) or k >= len(wanted) or have[k] != wanted[k])
            print(f"FAIL: {PAGE}:{begin + 1 + k}: section {name} is not what {SCRIPT} writes from "
                  f"{', '.join(sources)}; its first differing line:\n"
                  f"  page:      {have[k] if k < len(have) else '(section ends)'}\n"
                  f"  generated: {wanted[k] if k < len(wanted) else '(section ends)'}")
            failures += 1
        else:
            lines[begin:end + 1] = wanted
            print(f"{PAGE}: section {name} rewritten")

    text = "\n".join(lines) + "\n"
    if not check and text != page.read_text(encoding="utf-8"):
        page.write_text(text, encoding="utf-8")
    verb = "checked" if check else "written"
    print(f"{PAGE}: {len(SECTIONS)} generated section(s) {verb}; {failures} problem(s)"
          + (f" (run {SCRIPT} to rewrite the generated sections)" if check and differs else ""))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
