#!/usr/bin/env python3
"""The size rules of the layout (docs/architecture.md): no function over 80 lines and no file over
400 lines in src/, apps/, python/, bench/ or examples/, and a README.md of at most 12 KB (the quick
starts are parts of the example files; the rest is linked). Prints every breach and exits 1 if there is one.

A function is found by its body: a '{' that ends a line whose code (after the comments and strings
are blanked) has a ')' and does not start a control statement, a namespace, a class, a struct, an
enum or a lambda; its length runs from that line to the matching '}'. Lambdas count towards the
function they are in.

  scripts/check_layout.py [ROOT]
"""
import pathlib
import re
import sys

MAX_FUNCTION = 80
MAX_FILE = 400
MAX_README = 12 * 1024
CONTROL = re.compile(r"^\s*(\}\s*)?(if|else|for|while|switch|do|try|catch|namespace|struct|class|enum|union)\b")


def blank(text):
    """The text with comments, string and character literals replaced by spaces (lines kept)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("".join(ch if ch == "\n" else " " for ch in text[i:j]))
            i = j
        elif text.startswith('R"', i):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = text.find(")" + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append("".join(ch if ch == "\n" else " " for ch in text[i:j]))
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(" " * (min(j + 1, n) - i))
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(path):
    """(name line, first line, length) of every function body in the file."""
    text = "\n".join("" if l.lstrip().startswith("#") else l for l in path.read_text().split("\n"))
    lines = blank(text).split("\n")
    found, stack = [], []  # stack: (is_function, start line) per open brace
    for number, line in enumerate(lines, 1):
        for k, ch in enumerate(line):
            if ch == "{":
                head = line[:k]
                # The signature may span lines: look back to the previous ';', '{' or '}'.
                back, j = [head], number - 2
                while j >= 0 and not re.search(r"[;{}]\s*$", lines[j]) and number - j < 8:
                    back.insert(0, lines[j])
                    j -= 1
                signature = " ".join(back)
                is_lambda = re.search(r"\]\s*(\([^)]*\))?\s*(mutable\s*)?(->\s*[\w:<>]+\s*)?$", head.rstrip()) is not None
                in_function = any(f for f, _ in stack)
                is_function = (not in_function and ")" in signature and not CONTROL.match(signature.strip())
                               and not is_lambda and "=" not in head.split(")")[-1])
                stack.append((is_function, number))
            elif ch == "}" and stack:
                is_function, start = stack.pop()
                if is_function:
                    found.append((start, number - start + 1))
    return found


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent)
    breaches = []
    for folder in ("src", "apps", "python", "bench", "examples"):
        for path in sorted((root / folder).rglob("*")):
            if path.suffix not in (".cpp", ".h", ".inc"):
                continue
            count = len(path.read_text().splitlines())
            if count > MAX_FILE:
                breaches.append(f"{path.relative_to(root)}: {count} lines (files: at most {MAX_FILE})")
            for start, length in functions(path):
                if length > MAX_FUNCTION:
                    breaches.append(f"{path.relative_to(root)}:{start}: a function of {length} lines (at most {MAX_FUNCTION})")
    readme = (root / "README.md").stat().st_size
    if readme > MAX_README:
        breaches.append(f"README.md: {readme} bytes (at most {MAX_README}: link the rest)")
    for b in breaches:
        print(b)
    if breaches:
        print(f"check_layout: {len(breaches)} breach(es) of the size rules")
        return 1
    print("check_layout: every file and function within the size rules")
    return 0


if __name__ == "__main__":
    sys.exit(main())
