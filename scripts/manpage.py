#!/usr/bin/env python3
"""The manual page and the bash completion of robodamp, generated from its own --help.

    python3 scripts/manpage.py BUILD/apps/robodamp OUT_DIR

writes OUT_DIR/robodamp.1.gz (every command and subcommand with its options, as `--help` prints them) and
OUT_DIR/robodamp.bash (subcommands and options completed, files elsewhere). The help text is the one source:
a new option appears in both at the next build. Reproducible: gzip without a time stamp, the date from
SOURCE_DATE_EPOCH when set (Debian's convention), else the last commit's, else today.
"""
import datetime
import gzip
import os
import re
import subprocess
import sys


def run_help(exe, path):
    out = subprocess.run([exe, *path, "--help"], capture_output=True, text=True, check=True).stdout
    return out.replace(exe, "robodamp")


class Command:
    def __init__(self, path, text):
        self.path = path
        self.summary, self.usage, self.sections = "", "", []  # sections: (title, [(term, description)])
        self.subcommands = []
        self.parse(text)

    def parse(self, text):
        lines = text.splitlines()
        self.summary = lines[0].strip() if lines else ""
        section = None
        for line in lines[1:]:
            if line.startswith("Usage:"):
                self.usage = line[len("Usage:"):].strip()
            elif line and not line.startswith(" ") and line.endswith(":"):
                section = (line[:-1], [])
                self.sections.append(section)
            elif section is not None and line.startswith(" " * 30) and section[1]:
                term, desc = section[1][-1]
                section[1][-1] = (term, (desc + " " + line.strip()).strip())
            elif section is not None and line.strip():
                parts = re.split(r"\s{2,}", line.strip(), maxsplit=1)
                section[1].append((parts[0], parts[1] if len(parts) > 1 else ""))
        for title, entries in self.sections:
            if title == "Subcommands":
                self.subcommands = [term for term, _ in entries]

    def options(self):
        names = []
        for title, entries in self.sections:
            if title == "Options":
                for term, _ in entries:
                    for spec in term.split()[0].split(","):
                        if spec.startswith("-"):
                            names.append(spec)
        return names


def collect(exe, path=()):
    cmd = Command(list(path), run_help(exe, list(path)))
    found = [cmd]
    for sub in cmd.subcommands:
        found += collect(exe, (*path, sub))
    return found


def roff(text):
    text = text.replace("\\", "\\e").replace("-", "\\-")
    return "\\&" + text if text.startswith((".", "'")) else text


def man_page(commands, version, date):
    top = commands[0]
    out = [f'.TH ROBODAMP 1 "{date}" "robodamp {version}" "User Commands"',
           ".SH NAME", "robodamp \\- " + roff(top.summary.split(": ", 1)[-1]),
           ".SH SYNOPSIS", ".B robodamp", "[\\fIOPTIONS\\fR] \\fISUBCOMMAND\\fR [\\fIOPTIONS\\fR]",
           ".SH DESCRIPTION", roff(top.summary) + ".", ".PP",
           "Every number on the command line is checked against its unit and range; a refused one is named "
           "with both and the command exits with status 2 before anything runs.",
           ".SH COMMANDS"]
    for cmd in commands[1:]:
        out += [f'.SS "robodamp {roff(" ".join(cmd.path))}"', roff(cmd.summary)]
        if cmd.usage:
            out += [".PP", "Usage: " + roff(cmd.usage)]
        for title, entries in cmd.sections:
            if title == "Subcommands":
                continue
            out += [".PP", f"\\fI{roff(title)}\\fR"]
            for term, desc in entries:
                out += [".TP", f"\\fB{roff(term)}\\fR", roff(desc)]
    out += [".SH OPTIONS"]
    for title, entries in top.sections:
        if title == "Options":
            for term, desc in entries:
                out += [".TP", f"\\fB{roff(term)}\\fR", roff(desc)]
    out += [".SH FILES",
            ".TP", "\\fI/etc/robodamp/robodamp.yaml\\fR", "The cell's configuration the robodamp service runs.",
            ".TP", "\\fI/etc/robodamp/dashboard.yaml\\fR", "The dashboard service's configuration.",
            ".TP", "\\fI/usr/share/robodamp\\fR",
            "Shipped presets, robot models, milling jobs and HIL configurations. A file a configuration names "
            "that is not beside it is looked for here, in each folder of ROBODAMP_DATA_PATH first.",
            ".SH ENVIRONMENT",
            ".TP", "\\fBROBODAMP_DATA_PATH\\fR",
            "Folders (colon separated) searched before the installed data for the files a configuration names.",
            ".SH EXIT STATUS",
            "0 success; 2 a refused command line or configuration; 3 an unstable or refused design; "
            "4 a fault trip; 5 a run that never armed.",
            ".SH SEE ALSO", "\\fI/usr/share/doc/robodamp/\\fR (README.md, docs/)"]
    return "\n".join(out) + "\n"


def completion(commands):
    cases = []
    for cmd in commands:
        key = " ".join(cmd.path)
        words = " ".join(cmd.subcommands + cmd.options())
        cases.append(f'    "{key}") words="{words}" ;;')
    with_subs = " ".join(f'"{" ".join(c.path)}"' for c in commands if c.subcommands)
    return f"""# bash completion for robodamp, generated from its --help by scripts/manpage.py
_robodamp() {{
  local cur="${{COMP_WORDS[COMP_CWORD]}}" path="" i word words=""
  # The command path: the words before the cursor that name a command (stop at the first option).
  for ((i = 1; i < COMP_CWORD; i++)); do
    word="${{COMP_WORDS[i]}}"
    [[ "$word" == -* ]] && break
    case "$path" in
      ""|{with_subs or '""'}) ;;
      *) break ;;
    esac
    path="${{path:+$path }}$word"
  done
  case "$path" in
{chr(10).join(cases)}
    *) words="" ;;
  esac
  if [[ "$cur" == -* || ( -z "$path" ) ]]; then
    COMPREPLY=($(compgen -W "$words" -- "$cur"))
  else
    COMPREPLY=($(compgen -W "$words" -- "$cur") $(compgen -f -- "$cur"))
  fi
}}
complete -o filenames -F _robodamp robodamp
"""


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: manpage.py ROBODAMP_EXECUTABLE OUT_DIR")
    exe, out_dir = os.path.abspath(sys.argv[1]), sys.argv[2]
    commands = collect(exe)
    version = subprocess.run([exe, "--version"], capture_output=True, text=True, check=True).stdout.split()[1]
    if "SOURCE_DATE_EPOCH" in os.environ:
        date = datetime.datetime.fromtimestamp(int(os.environ["SOURCE_DATE_EPOCH"]), datetime.timezone.utc).date()
    else:
        git = subprocess.run(["git", "-C", os.path.dirname(os.path.abspath(__file__)), "log", "-1", "--format=%cs"],
                             capture_output=True, text=True)
        date = git.stdout.strip() or datetime.date.today().isoformat()
    os.makedirs(out_dir, exist_ok=True)
    with open(os.path.join(out_dir, "robodamp.1.gz"), "wb") as raw:
        with gzip.GzipFile(filename="", mode="wb", fileobj=raw, compresslevel=9, mtime=0) as z:
            z.write(man_page(commands, version, date).encode())
    with open(os.path.join(out_dir, "robodamp.bash"), "w") as f:
        f.write(completion(commands))
    print(f"manpage.py: {len(commands) - 1} commands into {out_dir}/robodamp.1.gz and robodamp.bash")


if __name__ == "__main__":
    main()
