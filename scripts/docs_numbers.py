#!/usr/bin/env python3
"""Documented numbers from one place (issue 55): the example outputs and tables in README.md and docs/*.md
that carry a marker are checked against what the product prints now, or written again from it.

  python3 scripts/docs_numbers.py            # check: exit 1 and say where a documented number drifted
  python3 scripts/docs_numbers.py --write    # renumber the marked blocks and tables from the product's output

Markers (an HTML comment, invisible on the rendered page, on the line before the block or table):

  <!-- docs-numbers: output ARGS... -->   the fenced block below is (an excerpt of) `robodamp ARGS...`'s
                                          standard output. Each documented line must be found in the output in
                                          order, with the same words; a line cut short with "..." matches the
                                          output line it starts; a line starting "$ " is the command as
                                          typed and is skipped. Its numbers must agree to 1 in their last
                                          printed digit.
  <!-- docs-numbers: output (wall ms) ARGS... -->   the same, but numbers followed by " ms" are the
                                          computer's time: rewritten, not compared.
  <!-- docs-numbers: transcript -->       each "$ robodamp ARGS..." line of the fenced block below is run, and
                                          the lines after it (to the next "$ ") are matched as above against
                                          what it printed on either stream, whatever its exit status (the
                                          refusals of hostile input).
  <!-- docs-numbers: bench-table -->      the four-preset bench table: each row's preset through `robodamp
                                          bench --json` (polarity, K_max, the measured / predicted improvement
                                          of each FRF, the saturating H22yy), to the digits printed.

The commands run in a scratch directory whose `config` is the repository's (nothing is written into the tree).
--write keeps every word of the documentation and replaces only its numbers, so an excerpt stays an excerpt.
"""
import argparse
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
NUMBER = re.compile(r"(?<![\w.])[-+−]?\d+(?:\.\d+)?(?:e[-+]?\d+)?(?![\w])")
MARKER = re.compile(r"^<!-- docs-numbers: (.*?) -->\s*$")


def numbers(line):
    return [(m.start(), m.end(), m.group(0)) for m in NUMBER.finditer(line)]


def value(text):
    return float(text.replace("−", "-"))


def last_digit(text):
    """One unit of the last printed digit (1e-3 for 1.106, 1e-7 for 3.153e-05)."""
    mantissa, _, exponent = text.replace("−", "-").lower().partition("e")
    decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
    return 10.0 ** (-decimals + (int(exponent) if exponent else 0))


def skeleton(line):
    """The line's words: numbers as '#', runs of spaces as one."""
    return re.sub(r"\s+", " ", NUMBER.sub("#", line)).strip()


def renumbered(doc_line, out_line):
    """The documented line with the output line's numbers written in its digits' places."""
    cut = doc_line.find("...")
    head, tail = (doc_line[:cut], doc_line[cut:]) if cut >= 0 else (doc_line, "")
    mine, theirs = numbers(head), numbers(out_line)
    parts, at = [], 0
    for (s, e, _), (_, _, text) in zip(mine, theirs):
        parts += [head[at:s], text.replace("-", "−") if "−" in head[s:e] else text]
        at = e
    return "".join(parts) + head[at:] + tail


def agree(doc_text, out_text):
    return abs(value(doc_text) - value(out_text)) <= last_digit(doc_text) * 1.0001


def wall_ms(line, end):
    return line[end:end + 3] == " ms"


def match_block(doc_lines, out_lines, where, skip_ms=False):
    """Each documented line against the output, in order: (problems, the block renumbered)."""
    problems, written, at = [], [], 0
    for n, line in enumerate(doc_lines):
        if not line.strip() or line.startswith("$ "):
            written.append(line)
            continue
        cut = line.find("...")
        want = skeleton(line[:cut] if cut >= 0 else line)
        found = None
        for k in range(at, len(out_lines)):
            have = skeleton(out_lines[k])
            if (have.startswith(want) if cut >= 0 else have == want):
                found = k
                break
        if found is None:
            problems.append(f"{where}, line {n + 1}: not in the output as written:\n    {line.strip()}")
            written.append(line)
            continue
        at = found + 1
        for (_, e, d), (_, _, o) in zip(numbers(line[:cut] if cut >= 0 else line), numbers(out_lines[found])):
            if not agree(d, o) and not (skip_ms and wall_ms(line, e)):
                problems.append(f"{where}, line {n + 1}: documented {d}, the product prints {o}:\n    {line.strip()}")
        written.append(renumbered(line, out_lines[found]))
    return problems, written


class Runner:
    def __init__(self, binary):
        self.binary = binary
        self.dir = tempfile.mkdtemp(prefix="robodamp-docs-numbers-")
        os.symlink(os.path.join(ROOT, "config"), os.path.join(self.dir, "config"))

    def run(self, args, both=False):
        r = subprocess.run([self.binary] + args, cwd=self.dir, capture_output=True, text=True, timeout=600)
        return r.returncode, (r.stdout + r.stderr) if both else r.stdout

    def close(self):
        shutil.rmtree(self.dir, ignore_errors=True)


def fmt_pct(v):
    return f"{v:.1f}"


def bench_row(runner, cells):
    """The bench table's row for the preset named in its first cell, as the product measures it now."""
    name = cells[0]
    out = os.path.join(runner.dir, f"bench_{name}.json")
    runner.run(["bench", "--config", f"config/presets/{name}.yaml", "--json", out])
    j = json.load(open(out))
    rows = {(r["name"], r["kind"]): r for r in j["rows"]}
    frf = [k for k in ("H11yy", "H21yy", "H22yy", "H11zz", "H21zz", "H22zz") if (k, "nominal") in rows][:3]
    pol = j["analysis"]["polarity"]
    row = [name, "+1" if pol > 0 else "−1", f"{j['analysis']['max_stable_gain_ns_per_m']:.0f}"]
    for k in frf:
        r = rows[(k, "nominal")]
        row.append(f"{fmt_pct(r['measured_improvement_pct'])} / {fmt_pct(r['predicted_improvement_pct'])} %")
    sat = rows.get((frf[-1], "saturating"))
    row.append(f"{fmt_pct(sat['measured_improvement_pct'])} %" if sat else "-")
    return row


def check_table(lines, start, runner, where):
    """The bench table from lines[start] (its header) on: (problems, the table rewritten)."""
    problems, written, k = [], [], start
    while k < len(lines) and lines[k].startswith("|"):
        cells = [c.strip() for c in lines[k].strip().strip("|").split("|")]
        if k - start >= 2:  # header and rule kept
            now = bench_row(runner, cells)
            for col, (d, o) in enumerate(zip(cells, now)):
                dn, on = [t for _, _, t in numbers(d)], [t for _, _, t in numbers(o)]
                if len(dn) != len(on) or not all(agree(a, b) for a, b in zip(dn, on)):
                    problems.append(f"{where}, the bench table, {cells[0]}: column {col + 1} documented '{d}', "
                                    f"the product measures '{o}'")
            written.append("| " + " | ".join(now) + " |")
        else:
            written.append(lines[k])
        k += 1
    return problems, written, k


def process(path, runner, write):
    lines = open(path, encoding="utf-8").read().split("\n")
    rel = os.path.relpath(path, ROOT)
    problems, out, k, checked = [], [], 0, 0
    while k < len(lines):
        m = MARKER.match(lines[k])
        out.append(lines[k])
        k += 1
        if not m:
            continue
        what = m.group(1).split()
        where = f"{rel}:{k + 1}"
        checked += 1
        if what[0] == "bench-table":
            p, written, k = check_table(lines, k, runner, where)
            problems += p
            out += written
        elif what[0] == "output":
            if not lines[k].startswith("```"):
                problems.append(f"{where}: the marker is not followed by a fenced block")
                continue
            end = lines.index("```", k + 1) if "```" in lines[k + 1:] else len(lines)
            skip_ms = what[1:3] == ["(wall", "ms)"]
            args = what[3:] if skip_ms else what[1:]
            status, stdout = runner.run(args)
            if status != 0:
                problems.append(f"{where}: `robodamp {' '.join(args)}` ended with status {status}")
            p, written = match_block(lines[k + 1:end], stdout.split("\n"), where, skip_ms)
            problems += p
            out += [lines[k]] + written + ["```"]
            k = end + 1
        elif what[0] == "transcript" and lines[k].startswith("```"):
            end = lines.index("```", k + 1) if "```" in lines[k + 1:] else len(lines)
            out.append(lines[k])
            at = k + 1
            while at < end:
                stop = next((j for j in range(at + 1, end) if lines[j].startswith("$ ")), end)
                typed = lines[at]
                args = shlex.split(typed[2:].split("  #")[0])[1:] if typed.startswith("$ robodamp") else None
                if args is None:
                    problems.append(f"{where}: a transcript line that is not '$ robodamp ...': {typed}")
                    out += lines[at:stop]
                else:
                    _, printed = runner.run(args, both=True)
                    p, written = match_block(lines[at + 1:stop], printed.split("\n"), f"{where} ({typed})")
                    problems += p
                    out += [typed] + written
                at = stop
            out.append("```")
            k = end + 1
        else:
            problems.append(f"{where}: unknown marker '{what[0]}' (output, transcript, bench-table)")
    if write and out != lines:
        open(path, "w", encoding="utf-8").write("\n".join(out))
    return problems, checked


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--write", action="store_true", help="renumber the marked blocks and tables")
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "apps", "robodamp"))
    a = ap.parse_args()
    runner = Runner(os.path.abspath(a.binary))
    try:
        files = [os.path.join(ROOT, "README.md")] + sorted(
            os.path.join(ROOT, "docs", f) for f in os.listdir(os.path.join(ROOT, "docs")) if f.endswith(".md"))
        problems, checked = [], 0
        for f in files:
            p, c = process(f, runner, a.write)
            problems += p
            checked += c
    finally:
        runner.close()
    for p in problems:
        print(p)
    verb = "rewritten" if a.write else "checked"
    print(f"docs_numbers: {checked} marked blocks and tables {verb}; {len(problems)} "
          f"{'drifted (now written)' if a.write else 'problems'}")
    return 1 if problems and not a.write else 0


if __name__ == "__main__":
    sys.exit(main())
