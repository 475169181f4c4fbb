#!/usr/bin/env bash
# Every accelviz command line that README.md and docs/*.md print is one the
# program still accepts: its subcommand, option names and option values as
# the command-line parser checks them (ACCELVIZ_PARSE_ONLY=1: read and
# checked, nothing run). Synopses with placeholders (SCENE, [--json], a|b,
# ...) and commands that build their arguments in the shell ($(...)) are
# left out; whatever else is in a code block or `inline code` is run through
# bash, so that braces and quotes expand as a reader's shell would expand them.
set -uo pipefail
accelviz="$(realpath "$1")"
src="$(realpath "$2")"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1

# The parse-only mode must still refuse what the parser refuses: otherwise every check below passes.
if ACCELVIZ_PARSE_ONLY=1 "$accelviz" bench x.glb --no-such-option 2>/dev/null; then
  echo "FAIL: ACCELVIZ_PARSE_ONLY=1 accepted an unknown option"; exit 1
fi
if ACCELVIZ_PARSE_ONLY=1 "$accelviz" bench x.glb y.glb 2>/dev/null; then
  echo "FAIL: ACCELVIZ_PARSE_ONLY=1 accepted two scenes"; exit 1
fi
subcommands=$("$accelviz" --help | awk '/^Subcommands:/{on=1; next} on && /^  [a-z]/{print $1} on && /^$/{exit}')
[ "$(wc -w <<<"$subcommands")" -ge 10 ] || { echo "FAIL: subcommands not found in --help: $subcommands"; exit 1; }

python3 - "$src" "$accelviz" "$subcommands" <<'PY'
import glob, os, re, shlex, subprocess, sys

src, accelviz, subcommands = sys.argv[1], sys.argv[2], set(sys.argv[3].split())


def snippets(path):
    """(line, text) of each fenced code block line (continuations joined) and each inline code span."""
    text = open(path, encoding="utf-8").read()
    found = []

    def fence(m):
        first = text[: m.start()].count("\n") + 2
        body = re.sub(r"\\\n\s*", " ", m.group(1))
        for i, line in enumerate(body.split("\n")):
            found.append((first + i, re.sub(r"^\$ ", "", line.strip())))
        return "\n" * m.group(0).count("\n")  # keep the line numbers of what follows

    rest = re.sub(r"```[A-Za-z]*\n(.*?)```", fence, text, flags=re.S)
    for m in re.finditer(r"`([^`]+)`", rest):
        found.append((rest[: m.start()].count("\n") + 1, re.sub(r"\s*\n\s*", " ", m.group(1))))
    return found


def command(text):
    """The accelviz command in TEXT, its words up to a pipe, redirection or list, as written (quotes
    kept for bash); None for none, a bare mention or a synopsis."""
    m = re.search(r"(?:^|[\s/])accelviz((?:\s+-q)?\s+([a-z][a-z-]*)(?:\s.*)?)$", text)
    if not m or m.group(2) not in subcommands:
        return None
    args = m.group(1)
    if re.search(r"\$|\.\.\.|…|\w\|\w", args):  # shell variables, elisions, alternatives (bvh|tlas)
        return None
    try:
        lex = shlex.shlex(args, posix=False, punctuation_chars="|&;<>")
        lex.whitespace_split = True
        words = list(lex)
    except ValueError:
        return None
    kept = []
    for i, w in enumerate(words):
        if set(w) <= set("|&;<>"):  # `| jq`, `> f`, `; ...`
            break
        if re.fullmatch(r"\d", w) and i + 1 < len(words) and words[i + 1].startswith(">"):  # `2> f`
            break
        kept.append(w)
    if len(kept) < 2:  # a bare mention: `accelviz bench`
        return None
    for w in kept:
        bare = w.strip("'\"")
        # Placeholders and synopsis marks: SCENE, WxH, M, DIR, [--json], --param NAME=V.
        if re.fullmatch(r"[A-Z][A-Z0-9_]*(x[A-Z])?", bare) or bare.startswith("[") or bare.endswith("]"):
            return None
        if re.search(r"(^|=)[A-Z][A-Z0-9_]*(=|$)", bare) and "builtin:" not in bare:
            return None
    return " ".join(kept)


paths = [os.path.join(src, "README.md")] + sorted(glob.glob(os.path.join(src, "docs", "*.md")))
checked, failed = 0, []
for path in paths:
    for line, text in snippets(path):
        args = command(text)
        if args is None:
            continue
        checked += 1
        env = dict(os.environ, ACCELVIZ_PARSE_ONLY="1", DISPLAY="", WAYLAND_DISPLAY="")
        r = subprocess.run(["bash", "-c", 'exec "$0" ' + args, accelviz], env=env, capture_output=True,
                           text=True, timeout=60)
        why = (r.stderr.strip().splitlines() or [""])[0]
        if r.returncode != 0 and why.endswith(" is required") and all(w.startswith("-") or prev.startswith("-")
                                                                     for prev, w in zip(args.split(), args.split()[1:])):
            checked -= 1  # prose naming options (`accelviz bench --json`), not a whole command
            continue
        if r.returncode != 0:
            why = (r.stderr.strip().splitlines() or ["(no message)"])[0]
            failed.append(f"{os.path.relpath(path, src)}:{line}: accelviz {args}\n    exit {r.returncode}: {why}")
for f in failed:
    print("FAIL:", f)
print(f"{checked} documented commands checked, {len(failed)} refused")
# The documentation prints some 90 whole commands: far fewer means the extraction broke.
if checked < 70:
    print("FAIL: fewer than 70 commands found; the extraction no longer reads the docs")
    sys.exit(1)
sys.exit(1 if failed else 0)
PY
