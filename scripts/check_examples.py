#!/usr/bin/env python3
"""Checks that every code block of README.md and docs/*.md that shows an example is that example's
file, or a part of it: a block right after a line `<!-- example: PATH -->` must hold PATH's text
exactly (PATH relative to the repository's root, a file under examples/); after
`<!-- example: PATH#NAME -->`, the lines of PATH between a comment line `[NAME]` and a comment line
`[/NAME]` (`// [NAME]` in C++, `# [NAME]` in Python), less their common indentation. With --fix,
rewrites the blocks from the files instead. Exits 1 naming each block that differs, 2 on a marker
without a block, file or part.

    python3 scripts/check_examples.py [--fix]
"""
import pathlib
import re
import sys
import textwrap

ROOT = pathlib.Path(__file__).resolve().parent.parent
MARKER = re.compile(r"^<!-- example: (\S+) -->$")


def part(text, name, path):
    """The lines of `text` between the comment lines [name] and [/name], dedented."""
    lines = text.rstrip("\n").split("\n")
    mark = lambda tag: [i for i, l in enumerate(lines) if re.fullmatch(r"\s*(//|#) \[" + re.escape(tag) + r"\]", l)]
    begin, end = mark(name), mark("/" + name)
    if len(begin) != 1 or len(end) != 1 or end[0] <= begin[0]:
        raise SystemExit(f"check_examples: {path} has no single part [{name}] ... [/{name}]")
    return textwrap.dedent("\n".join(lines[begin[0] + 1:end[0]])).split("\n")


def blocks(lines):
    """(marker line, path, first body line, end fence line) of each marked block."""
    for i, line in enumerate(lines):
        m = MARKER.match(line.strip())
        if not m:
            continue
        if i + 1 >= len(lines) or not lines[i + 1].startswith("```"):
            raise SystemExit(f"check_examples: line {i + 1}: '{m.group(1)}' is not followed by a fenced block")
        end = next((j for j in range(i + 2, len(lines)) if lines[j].startswith("```")), None)
        if end is None:
            raise SystemExit(f"check_examples: line {i + 2}: a fenced block that never closes")
        yield i, m.group(1), i + 2, end


def main():
    fix = "--fix" in sys.argv[1:]
    docs = [ROOT / "README.md"] + sorted((ROOT / "docs").glob("*.md"))
    bad, seen = [], 0
    for doc in docs:
        lines = doc.read_text().split("\n")
        out, last = [], 0
        for _, shown, first, end in blocks(lines):
            seen += 1
            path, _, name = shown.partition("#")
            file = ROOT / path
            if not path.startswith("examples/") or not file.is_file():
                print(f"check_examples: {doc.relative_to(ROOT)}: '{path}' is not a file under examples/", file=sys.stderr)
                sys.exit(2)
            text = file.read_text()
            want = part(text, name, path) if name else text.rstrip("\n").split("\n")
            if lines[first:end] != want:
                bad.append(f"{doc.relative_to(ROOT)}: the block of {path} differs from the file")
            out += lines[last:first] + want
            last = end
        out += lines[last:]
        if fix and out != lines:
            doc.write_text("\n".join(out))
    if fix:
        print(f"check_examples: {seen} example blocks written from their files")
        return 0
    for b in bad:
        print(f"check_examples: {b}", file=sys.stderr)
    if bad:
        return 1
    if seen == 0:
        print("check_examples: no example block found", file=sys.stderr)
        return 1
    print(f"check_examples: {seen} example blocks in README.md and docs/ are their files")
    return 0


if __name__ == "__main__":
    sys.exit(main())
