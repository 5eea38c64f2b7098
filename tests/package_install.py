#!/usr/bin/env python3
"""Package.InstallRulesPutEveryFileWhereTheUnitsAndTheManualSay (tests/CMakeLists.txt).

    python3 tests/package_install.py BUILD_DIR SOURCE_DIR

What the Debian package is made of (packaging/CMakeLists.txt), without building a second tree: the build's
install rules run into a folder of this test's own (DESTDIR, prefix /usr, as scripts/package.sh installs),
then
  - every file the package must hold is there, nothing of the sources is under /usr/share/robodamp;
  - the files under /etc are exactly packaging/debian/conffiles;
  - the installed binary, run from a folder outside the tree with the installed data first on
    ROBODAMP_DATA_PATH, reads the installed cell and dashboard configurations (the presets they name found
    in the installed data) and takes its default cell configuration from there;
  - the manual page has every command and every option `--help` prints; the completion completes them;
  - systemd-analyze verify accepts the three units (where it is installed) with nothing to say.
The .deb itself (CPack, dpkg-shlibdeps, lintian) is scripts/package.sh's: a second build of the whole tree
does not fit the suite's time.
"""
import gzip
import os
import re
import shutil
import subprocess
import sys
import tempfile

failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def run(args, **kw):
    return subprocess.run(args, capture_output=True, text=True, timeout=300, **kw)


def main():
    build, source = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    tmp = tempfile.mkdtemp(prefix="robodamp-package-")
    try:
        root = os.path.join(tmp, "root")
        r = run(["cmake", "--install", build, "--prefix", "/usr"], env={**os.environ, "DESTDIR": root})
        check(r.returncode == 0, "cmake --install into DESTDIR: " + r.stderr[-500:])
        inside = lambda p: os.path.join(root, p.lstrip("/"))
        for p in ["/usr/bin/robodamp", "/usr/share/robodamp/presets/horizontal_c2.yaml",
                  "/usr/share/robodamp/robots/compact_three_link.yaml",
                  "/usr/share/robodamp/milling/industrial_robot_aluminium.yaml",
                  "/usr/share/robodamp/hil_horizontal_c2.yaml", "/etc/robodamp/robodamp.yaml",
                  "/etc/robodamp/dashboard.yaml", "/lib/systemd/system/robodamp.service",
                  "/lib/systemd/system/robodamp-can.service", "/lib/systemd/system/robodamp-dashboard.service",
                  "/usr/share/man/man1/robodamp.1.gz", "/usr/share/bash-completion/completions/robodamp",
                  "/usr/share/doc/robodamp/copyright", "/usr/share/doc/robodamp/changelog.gz",
                  "/usr/share/doc/robodamp/README.md", "/usr/share/doc/robodamp/docs/deployment.md"]:
            check(os.path.isfile(inside(p)), "installed: " + p)
        stray = [os.path.join(d, f) for d, _, fs in os.walk(inside("/usr/share/robodamp")) for f in fs
                 if f.endswith((".cpp", ".hpp", ".py")) or f == "CMakeLists.txt"]
        check(not stray, "no source files in /usr/share/robodamp: " + ", ".join(stray[:3]))
        with open(os.path.join(source, "packaging/debian/conffiles")) as f:
            conffiles = sorted(l.strip() for l in f if l.strip())
        etc = sorted("/" + os.path.relpath(os.path.join(d, f), root) for d, _, fs in os.walk(inside("/etc")) for f in fs)
        check(etc == conffiles, f"the files under /etc are the conffiles: {etc} vs {conffiles}")

        # The installed binary, outside the tree, the installed data first.
        exe = inside("/usr/bin/robodamp")
        away = os.path.join(tmp, "away")
        os.makedirs(away)
        env = {**os.environ, "ROBODAMP_DATA_PATH": inside("/usr/share/robodamp")}
        for conf in ["/etc/robodamp/robodamp.yaml", "/etc/robodamp/dashboard.yaml"]:
            r = run([exe, "check-config", inside(conf)], cwd=away, env=env)
            check(r.returncode == 0, f"check-config {conf}: {r.stdout[-300:]}{r.stderr[-300:]}")
        r = run([exe, "analyze"], cwd=away, env=env)
        check(r.returncode == 0 and ("of " + inside("/usr/share/robodamp/presets/horizontal_c2.yaml")) in r.stdout,
              "the default cell configuration is the installed preset: " + r.stdout.splitlines()[0] if r.stdout else "")

        # The manual page and the completion.
        with gzip.open(inside("/usr/share/man/man1/robodamp.1.gz"), "rt") as f:
            page = f.read().replace("\\-", "-")
        top = run([exe, "--help"]).stdout
        commands = re.findall(r"^  ([a-z][a-z-]+) {2,}", top.split("Subcommands:")[1], re.M)
        check(len(commands) >= 20, f"--help lists the commands ({len(commands)})")
        for c in commands:
            check(f'.SS "robodamp {c}"' in page, f"the manual page has robodamp {c}")
        bench_options = re.findall(r"^  (?:-\w,)?(--[a-z-]+)", run([exe, "bench", "--help"]).stdout, re.M)
        check(bench_options and all(o in page for o in bench_options), "the manual page has bench's options")
        completion = inside("/usr/share/bash-completion/completions/robodamp")
        for words, cword, want in [("robodamp be", 1, "bench"), ("robodamp bench --cut", 2, "--cut-speeds"),
                                   ("robodamp identify --fr", 2, "--frf")]:
            script = (f"source {completion}; COMP_WORDS=({words}); COMP_CWORD={cword}; _robodamp; "
                      'printf "%s\\n" "${COMPREPLY[@]}"')
            got = run(["bash", "-c", script]).stdout.split()
            check(want in got, f"completion of '{words}' offers {want}: {got}")

        # The units, as systemd reads them (the installed binary where they name /usr/bin/robodamp).
        if shutil.which("systemd-analyze"):
            units = os.path.join(tmp, "units")
            os.makedirs(units)
            for u in ["robodamp.service", "robodamp-can.service", "robodamp-dashboard.service"]:
                with open(inside("/lib/systemd/system/" + u)) as f:
                    text = f.read().replace("/usr/bin/robodamp", exe)
                with open(os.path.join(units, u), "w") as f:
                    f.write(text)
            r = run(["systemd-analyze", "verify", "--man=no"] + [os.path.join(units, u) for u in sorted(os.listdir(units))],
                    env={**os.environ, "SYSTEMD_LOG_LEVEL": "notice"})
            check(r.returncode == 0 and not (r.stdout + r.stderr).strip(),
                  "systemd-analyze verify accepts the units: " + (r.stdout + r.stderr)[:500])
        else:
            print("skip systemd-analyze verify: not installed")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"{len(failures)} failures")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
