#!/usr/bin/env python3
"""Lists the longest function bodies of the C++ sources: lines from a definition's first line
to its closing brace, lambdas and local classes counted in their enclosing function.

usage: scripts/function_lengths.py [-n COUNT] [PATH ...]   (default: the tracked *.cpp, *.h)
"""
import argparse
import re
import subprocess
import sys

SCOPE_WORDS = re.compile(r"^\s*(?:template\s*<.*>\s*)?(namespace|class|struct|union|enum)\b")
CONTROL = re.compile(r"^\s*(if|for|while|switch|catch|do|else|return)\b")


def strip(text):
    """The text with comments, string and character literals blanked (newlines kept)."""
    out = []
    i, n = 0, len(text)
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
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'R"([^(]*)\(', text[i:])
            end = text.find(")" + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum():  # digit separator 1'000
                out.append(" ")
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(path):
    text = strip(open(path, encoding="utf-8", errors="replace").read())
    text = re.sub(r"(?m)^[ \t]*#.*$", lambda m: " " * len(m.group(0)), text)  # preprocessor lines
    stack = []  # per open brace: "scope" (namespace/class/...) or "body" (function or block)
    header_start = 0
    found = []
    for i, c in enumerate(text):
        if c == "{":
            header = text[header_start:i]
            in_body = any(kind[0] == "body" for kind in stack)
            if in_body:
                stack.append(("block", None))
            elif SCOPE_WORDS.match(header) and "(" not in header.split("{")[0].split("=")[0]:
                stack.append(("scope", None))
            elif "(" in header and not CONTROL.match(header) and not header.rstrip().endswith("="):
                start = i - len(header) + (len(header) - len(header.lstrip()))
                name = re.findall(r"([~\w:<>]+)\s*\(", header)
                stack.append(("body", (text.count("\n", 0, start) + 1, name[0] if name else "?")))
            else:
                stack.append(("scope", None))  # an initializer or array at namespace scope
            header_start = i + 1
        elif c == "}":
            if stack:
                kind, info = stack.pop()
                if kind == "body":
                    end = text.count("\n", 0, i) + 1
                    found.append((end - info[0] + 1, path, info[0], info[1]))
            header_start = i + 1
        elif c == ";":
            if not any(kind[0] == "body" for kind in stack):
                header_start = i + 1
    return found


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("-n", type=int, default=10)
    parser.add_argument("paths", nargs="*")
    args = parser.parse_args()
    paths = args.paths or subprocess.run(["git", "ls-files", "*.cpp", "*.h"], capture_output=True, text=True,
                                         check=True).stdout.split()
    rows = []
    for p in paths:
        rows.extend(functions(p))
    rows.sort(key=lambda r: (-r[0], r[1], r[2]))
    for length, path, line, name in rows[: args.n]:
        print(f"{length:5d}  {path}:{line}  {name}")


if __name__ == "__main__":
    sys.exit(main())
