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


# Placeholders in synopses and figures' commands, standing for a value of their kind: a command that
# names them is checked with these (`--out DIR`, `'builtin:soup?size=N'`, `--seed S`).
PLACEHOLDERS = {"DIR": "out", "SCENE": "builtin:teapot", "FILE": "f.obj", "MESH": "bunny.glb", "ASSET": "bunny.glb",
                "OUT": "out.png", "N": "2", "T": "1", "J": "1", "R": "10", "A": "1", "L": "4", "M": "explode",
                "ISA": "avx2", "X": "1", "Y": "1", "WxH": "8x8", "NAME": "teapot", "F": "2", "K": "2"}
PLACEHOLDER = r"(?<![A-Za-z0-9_])(%s)(?![A-Za-z0-9_])" % "|".join(sorted(PLACEHOLDERS, key=len, reverse=True))


def command(text):
    """The accelviz command in TEXT, its words up to a pipe, redirection or list, as written (quotes
    kept for bash; placeholders given a value); None for none, a bare mention or a synopsis."""
    m = re.search(r"(?:^|[\s/])accelviz((?:\s+-q)?\s+([a-z][a-z0-9._:?=&/-]*)(?:\s.*)?)$", text)
    if not m:
        return None
    args = m.group(1)
    # Shell variables and loops, elisions, alternatives (bvh|tlas), optional parts, a description in
    # a column beside it: a synopsis.
    if re.search(r"\$|\.\.\.|…|\w\|\w|\[|<[a-z]", args) or re.search(r"accelviz {3,}\S|\S {3,}\S", text):
        return None
    try:
        lex = shlex.shlex(args, posix=False, punctuation_chars="|&;<>")
        lex.whitespace_split = True
        words = list(lex)
    except ValueError:
        return None
    kept, given = [], []
    for i, w in enumerate(words):
        if set(w) <= set("|&;<>"):  # `| jq`, `> f`, `; ...`
            break
        if re.fullmatch(r"\d", w) and i + 1 < len(words) and words[i + 1].startswith(">"):  # `2> f`
            break
        given.append(w)
        kept.append(re.sub(PLACEHOLDER, lambda p: PLACEHOLDERS[p.group(1)], w))
    if len(kept) < 2:  # a bare mention: `accelviz bench`
        return None
    for w in kept:
        if re.search(r"(?<![A-Za-z])[A-Z]{1,}(?![a-z])", w.strip("'\"")) and not re.search(r"[a-z]", w):
            return None  # another placeholder (an upper-case word of its own)
    return " ".join(kept), given


paths = [os.path.join(src, "README.md")] + sorted(glob.glob(os.path.join(src, "docs", "*.md")))
checked, failed = 0, []
for path in paths:
    for line, text in snippets(path):
        found = command(text)
        if found is None:
            continue
        args, given = found
        checked += 1
        env = dict(os.environ, ACCELVIZ_PARSE_ONLY="1", DISPLAY="", WAYLAND_DISPLAY="")
        r = subprocess.run(["bash", "-c", 'exec "$0" ' + args, accelviz], env=env, capture_output=True,
                           text=True, timeout=60)
        why = (r.stderr.strip().splitlines() or [""])[0]
        # Prose naming a subcommand's options (`accelviz bench --json`): no scene or file among its
        # words, and refused only for the missing positional argument.
        names_a_file = any(re.search(r"[./:]", w) for w in given[1:])
        if r.returncode != 0 and why.endswith(" is required") and not names_a_file:
            checked -= 1
            continue
        if r.returncode != 0:
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
