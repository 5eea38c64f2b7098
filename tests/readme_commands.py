#!/usr/bin/env python3
"""Every command the README and docs/commands.md (the commands one by one, moved out of the README) show in a
```sh block runs as written (issue 55), or is set aside with its reason.

  python3 tests/readme_commands.py BINARY_DIR [FILE.md ...]

The commands run in order, each in one scratch directory whose `config` and `build` are the repository's (so
`./build/apps/robodamp` and `config/...` resolve as in a clone), with BINARY_DIR first on PATH (the README's
PATH line: a bare `robodamp` works) and /tmp/ moved into the scratch directory: nothing is written into the
tree. Each must end with status 0 within 180 s. Set aside, and listed: lines with a placeholder (FILE, JOB,
[--option], a|b, ...), blocks that start a second process with `&` (the HIL pairs: tests/test_hil*.cpp), the
set-up scripts themselves (CI runs them from a fresh clone), installing the package (apt-get), and the commands that take minutes (named below;
their tests are named too).
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PLACEHOLDER = re.compile(r"\[|\]|\.\.\.|(?<![\w-])[A-Z][A-Z0-9_]*(?:\.yaml)?(?![\w])|\s\|\s")
OUTPUTS = {"--out", "-o", "--json", "--plot-dir", "--modes-uff", "--record"}
# Minutes each: run by their own tests and scripts.
SLOW = {
    "commission": "minutes (tests/test_commission.cpp, scripts in docs/identification.md)",
    "tune": "minutes (tests/test_tune.cpp)",
    "schedule": "about a minute (tests/test_speed_schedule.cpp)",
    "dashboard": "serves until stopped (tests/browser/test_dashboard.py)",
    "monitor": "follows a cell until stopped (tests/test_dds.cpp)",
}


def commands(readme):
    """(line number, command) of each ```sh block, continuation lines joined; and the blocks' set-aside reasons."""
    lines = open(readme, encoding="utf-8").read().split("\n")
    out, k = [], 0
    while k < len(lines):
        if lines[k].strip() != "```sh":
            k += 1
            continue
        block, start = [], k + 2
        k += 1
        while not lines[k].startswith("```"):
            block.append((k + 1, lines[k]))
            k += 1
        joined, n0 = [], None
        for n, text in block:
            n0 = n0 or n
            if text.rstrip().endswith("\\"):
                joined.append(text.rstrip()[:-1])
                continue
            joined.append(text)
            background = any(re.search(r"&\s*(#.*)?$", t) for _, t in block)
            out.append((n0, " ".join(s.strip() for s in joined), background, start))
            joined, n0 = [], None
    return out


def reason_to_skip(command, in_background_block):
    code = command.split("  #")[0].split(" # ")[0]
    if in_background_block:
        return "a block with a second process (`&`): the HIL pairs, tests/test_hil*.cpp"
    if code.startswith("bash scripts/") or code.startswith("echo ") or code.startswith("printf "):
        return "set-up or the dashboard's users: CI runs the scripts from a fresh clone (.ci/run)"
    if code.startswith("apt-get "):
        return "installs on the machine: scripts/package.sh --try-install does (docs/deployment.md, section 6)"
    if PLACEHOLDER.search(code):
        return "a placeholder to fill in"
    words = code.split()
    sub = words[1] if len(words) > 1 else ""
    if sub in SLOW:
        return SLOW[sub]
    for before, word in zip(words, words[1:]):  # an input file the reader brings (export.uff, measured.yaml)
        if (re.search(r"\.(uff|unv|yaml|csv|wav|rec|rdrec)$", word) and before not in OUTPUTS and not word.startswith("/tmp/")
                and not os.path.exists(os.path.join(ROOT, word))):
            return f"{word}: a file of the reader's own"
    return None


TIMING_TRIES = 3


def run_once(run, scratch, env):
    """One run of a command in the scratch folder: its exit status, the tail of its output and 1 (the tries)."""
    try:
        r = subprocess.run(["bash", "-c", run], cwd=scratch, env=env, capture_output=True, text=True, timeout=180)
        return r.returncode, (r.stdout + r.stderr)[-1500:], 1
    except subprocess.TimeoutExpired:
        return "timeout (180 s)", "", 1


def main():
    binary_dir = os.path.abspath(sys.argv[1])
    pages = sys.argv[2:] or [os.path.join(ROOT, "README.md"), os.path.join(ROOT, "docs", "commands.md")]
    scratch = tempfile.mkdtemp(prefix="robodamp-readme-")
    for name in ("config", "build"):
        os.symlink(os.path.join(ROOT, name), os.path.join(scratch, name))
    env = dict(os.environ, PATH=binary_dir + os.pathsep + os.environ.get("PATH", ""))
    ran, failed, skipped = 0, [], []
    try:
        blocks = [(os.path.relpath(page, ROOT),) + c for page in pages for c in commands(page)]
        for page, line, command, background, _ in blocks:
            line = f"{page}:{line}"
            why = reason_to_skip(command, background)
            if why:
                skipped.append((line, command, why))
                continue
            run = command.replace("/tmp/", scratch + "/tmp/")
            os.makedirs(os.path.join(scratch, "tmp"), exist_ok=True)
            status, tail, tries = run_once(run, scratch, env)
            # A wall-clock run on a machine whose other cores run the rest of the suite can lose its rate: the loop
            # then trips `overruns` (exit 4), as the product should. That says nothing about the command as written,
            # so such a run is tried again, at most TIMING_TRIES times, and the retries are printed.
            while status == 4 and "tripped: overruns" in tail and tries < TIMING_TRIES:
                print(f"{line}: the wall-clock loop lost its rate on this loaded machine (tripped: overruns): again")
                status, tail, _ = run_once(run, scratch, env)
                tries += 1
            ran += 1
            print(f"{line}: {'ok' if status == 0 else 'FAILED'}: {command}")
            if status != 0:
                failed.append((line, command, status, tail))
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    for line, command, why in skipped:
        print(f"{line}: set aside ({why}): {command}")
    for line, command, status, tail in failed:
        print(f"\n{line}: `{command}` ended with {status}:\n{tail}")
    print(f"readme_commands: {ran} run, {len(failed)} failed, {len(skipped)} set aside")
    if ran < 9:
        print("readme_commands: fewer than 9 commands ran: the pages' blocks were not read as expected")
        return 1
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
