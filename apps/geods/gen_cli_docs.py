#!/usr/bin/env python3
"""Writes the man page geods.1 and the bash completion of the geods CLI from its
own --help output (every command and subcommand, recursively), so neither can
drift from the CLI.

Usage: gen_cli_docs.py GEODS_EXECUTABLE OUT_DIR   (writes OUT_DIR/geods.1, OUT_DIR/geods.bash)
"""
import re
import subprocess
import sys
from dataclasses import dataclass, field

NAME_COLUMN = 30  # CLI11 pads the names of options and subcommands to this column


@dataclass
class Entry:
    names: list        # e.g. ["-o", "--output"] or ["mesh"]
    spec: str          # the rest of the name column, e.g. "TEXT REQUIRED"
    text: str          # description
    choices: list = field(default_factory=list)  # values of TEXT:{a,b,c}


@dataclass
class Command:
    path: list                 # e.g. [] for geods, ["shapes", "index"]
    summary: str = ""
    description: str = ""
    usage: str = ""
    positionals: list = field(default_factory=list)
    options: list = field(default_factory=list)
    commands: list = field(default_factory=list)


def parse_help(text, path):
    """Parses CLI11's help of one (sub)command."""
    command = Command(path)
    section, description = None, []
    entries = {"Positionals": command.positionals, "Options": command.options, "Subcommands": []}
    subcommands = []
    for line in text.splitlines():
        if re.match(r"^[A-Z][A-Za-z ]*:$", line):
            section = line[:-1]
            continue
        if line.startswith("Usage:"):
            words = line.split(None, 2)  # Usage: /path/to/geods shapes index [OPTIONS] collection
            command.usage = "geods " + (words[2] if len(words) > 2 else "")
            continue
        if section is None:
            if line.strip():
                description.append(line.strip())
            continue
        if not line.strip():
            continue
        if line.startswith(" " * NAME_COLUMN) and entries.get(section):
            last = entries[section][-1]  # a description on its own line, or a continued one
            last.text = (last.text + " " + line.strip()).strip()
            continue
        match = re.match(r"^  (\S.*?)(?: {2,}(.*))?$", line)
        if not match or section not in entries:
            raise SystemExit(f"gen_cli_docs.py: cannot read this help line of {' '.join(['geods'] + path)}: {line!r}")
        head, text_ = match.group(1), match.group(2) or ""
        first, _, spec = head.partition(" ")
        choices = re.findall(r":\{([^}]*)\}", spec)
        entry = Entry(first.split(","), spec, text_, choices[0].split(",") if choices else [])
        entries[section].append(entry)
        if section == "Subcommands":
            subcommands.append(entry)
    command.description = "\n".join(description)
    return command, subcommands


def read_commands(cli, path=()):
    path = list(path)
    text = subprocess.run([cli, *path, "--help"], capture_output=True, text=True, check=True).stdout
    command, subcommands = parse_help(text, path)
    for sub in subcommands:
        child = read_commands(cli, path + [sub.names[0]])
        child.summary = sub.text
        command.commands.append(child)
    return command


def walk(command):
    yield command
    for child in command.commands:
        yield from walk(child)


# --- man page --------------------------------------------------------------------

def roff(text):
    text = text.replace("\\", "\\e").replace("-", "\\-")
    return "\n".join(("\\&" + line) if line[:1] in ".'" else line for line in text.split("\n"))


def man_entry(entry, positional):
    if positional:
        head = f"\\fI{roff(entry.names[0])}\\fR"
    else:
        head = ", ".join(f"\\fB{roff(name)}\\fR" for name in entry.names)
    if entry.spec:
        head += " " + roff(entry.spec)
    return [".TP", head, roff(entry.text) or "\\&"]


def man_page(root, version):
    lines = [f'.TH GEODS 1 "" "{roff(version)}" "User Commands"',
             ".SH NAME", "geods \\- " + roff(root.description.split("\n")[0].partition(": ")[2].rstrip(".")),
             ".SH SYNOPSIS", ".B geods", "[\\fIOPTIONS\\fR] \\fICOMMAND\\fR [\\fICOMMAND OPTIONS\\fR]",
             ".SH DESCRIPTION", roff(root.description), ".SH OPTIONS"]
    for entry in root.options:
        lines += man_entry(entry, False)
    lines += [".SH COMMANDS", "Every command takes \\fB\\-\\-json\\fR (one JSON object instead of the summary) "
              "and \\fB\\-\\-threads\\fR \\fIN\\fR; \\fBgeods\\fR \\fICOMMAND\\fR \\fB\\-\\-help\\fR prints the "
              "same help as this page."]
    for command in walk(root):
        if not command.path:
            continue
        lines += [f'.SS "{roff(" ".join(["geods"] + command.path))}"', roff(command.summary), ".PP",
                  "Usage: \\fB" + roff(command.usage) + "\\fR"]
        if command.commands:
            lines += [".PP", "Commands: " + ", ".join(f"\\fB{roff(c.path[-1])}\\fR" for c in command.commands) + "."]
        for entry in command.positionals:
            lines += man_entry(entry, True)
        for entry in command.options:
            lines += man_entry(entry, False)
    lines += [".SH EXIT STATUS", "0 on success, 1 when a step failed (such as a demo step), "
              "2 on bad arguments or bad input (one line on standard error).",
              ".SH SEE ALSO", "The geods documentation (docs/README.md of the source tree), and the Python "
              "package: \\fBpython3 \\-m geods \\-\\-version\\fR."]
    return "\n".join(lines) + "\n"


# --- bash completion -------------------------------------------------------------

def bash_word(text):
    return "'" + text.replace("'", "'\\''") + "'"


def bash_completion(root):
    subs, opts, values = {}, {}, {}
    for command in walk(root):
        key = " ".join(["geods"] + command.path)
        subs[key] = " ".join(c.path[-1] for c in command.commands)
        opts[key] = " ".join(name for e in command.options for name in e.names)
        for entry in command.options:
            if entry.choices:
                for name in entry.names:
                    values[f"{key}|{name}"] = " ".join(entry.choices)
    table = lambda d: " ".join(f"[{bash_word(k)}]={bash_word(v)}" for k, v in sorted(d.items()))
    return f"""# bash completion of geods: commands, their options and the values of options with
# a fixed set of values. Generated from `geods --help` by apps/geods/gen_cli_docs.py.
_geods() {{
  local -A subs=({table(subs)})
  local -A opts=({table(opts)})
  local -A values=({table(values)})
  local cur=${{COMP_WORDS[COMP_CWORD]}} prev= path=geods word i
  ((COMP_CWORD > 0)) && prev=${{COMP_WORDS[COMP_CWORD-1]}}
  # The command path: the words before the cursor that name a (sub)command.
  for ((i = 1; i < COMP_CWORD; i++)); do
    word=${{COMP_WORDS[i]}}
    if [[ " ${{subs[$path]}} " == *" $word "* ]]; then
      path="$path $word"
    fi
  done
  COMPREPLY=()
  if [[ -n ${{values[$path|$prev]+set}} ]]; then
    COMPREPLY=($(compgen -W "${{values[$path|$prev]}}" -- "$cur"))
  elif [[ $cur == -* ]]; then
    COMPREPLY=($(compgen -W "${{opts[$path]}}" -- "$cur"))
  elif [[ -n ${{subs[$path]}} ]]; then
    COMPREPLY=($(compgen -W "${{subs[$path]}}" -- "$cur"))
  fi  # otherwise file names (complete -o default)
  return 0
}}
complete -o default -F _geods geods
"""


def main():
    if len(sys.argv) != 3:
        raise SystemExit(__doc__)
    cli, out = sys.argv[1], sys.argv[2]
    version = subprocess.run([cli, "--version"], capture_output=True, text=True, check=True).stdout.strip()
    root = read_commands(cli)
    if not root.commands:
        raise SystemExit("gen_cli_docs.py: found no commands in `geods --help`")
    with open(f"{out}/geods.1", "w") as f:
        f.write(man_page(root, version))
    with open(f"{out}/geods.bash", "w") as f:
        f.write(bash_completion(root))


if __name__ == "__main__":
    main()
