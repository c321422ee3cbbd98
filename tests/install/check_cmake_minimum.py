#!/usr/bin/env python3
"""Checks that CMake files use nothing newer than the CMake version kdm asks for.

Looks each command, file()/string()/list()/cmake_path() sub-command, `cmake -E` tool, generator
expression and CMAKE_/PROJECT_ variable the files use up in the running CMake's own documentation
(its Help directory), and names every use whose `versionadded` is above the minimum. Keyword options
of a command are not checked. Exits 77 (skipped) where the documentation is not installed.

Usage: check_cmake_minimum.py MINIMUM HELP_DIR FILE...
"""
import os
import re
import sys


def version(text):
    return tuple(int(part) for part in text.split("."))


def added_after(lines, start):
    """The versionadded directly after the signature or title that starts at lines[start], or None."""
    i = start + 1
    while i < len(lines) and (not lines[i].strip() or
                              (lines[i][:1].isspace() and not lines[i].strip().startswith(".."))):
        i += 1
    match = i < len(lines) and re.match(r"\s*\.\. versionadded:: ([0-9.]+)", lines[i])
    return version(match.group(1)) if match else None


def read(path):
    try:
        with open(path, encoding="utf-8") as f:
            return f.read().splitlines()
    except OSError:
        return None


def entry_added(lines, pattern):
    """The versionadded of the doc's entry for pattern: its first match (a synopsis marks its names up as
    links, which pattern does not match; later matches are examples)."""
    first = next((i for i, line in enumerate(lines) if re.match(pattern, line)), None)
    return (added_after(lines, first) or (0,)) if first is not None else None


def page_added(path):
    """The versionadded under a page's title (a command's or a variable's page)."""
    lines = read(path)
    if lines is None:
        return None
    title = next((i for i, line in enumerate(lines) if re.match(r"^[-=^~]{3,}$", line)), None)
    return (added_after(lines, title) or (0,)) if title is not None else None


def main():
    minimum, help_dir, files = version(sys.argv[1]), sys.argv[2], sys.argv[3:]
    if not os.path.isdir(os.path.join(help_dir, "command")):
        print(f"no CMake documentation at {help_dir}: skipped")
        return 77
    cmake_1 = read(os.path.join(help_dir, "manual", "cmake.1.rst")) or []
    genex_7 = read(os.path.join(help_dir, "manual", "cmake-generator-expressions.7.rst")) or []
    sub_docs = {c: read(os.path.join(help_dir, "command", c + ".rst")) or []
                for c in ("file", "string", "list", "cmake_path")}
    failed = False
    for path in files:
        uses = {}  # what -> the version that added it
        with open(path, encoding="utf-8") as f:
            # Comments out: a comment may name what the code avoids.
            text = "\n".join(re.sub(r"(^|\s)#(\s.*)?$", "", line) for line in f.read().splitlines())
        for name in set(re.findall(r"(?<![\w$<])([A-Za-z_]\w*)\s*\(", text)):
            uses[f"{name.lower()}()"] = page_added(os.path.join(help_dir, "command", name.lower() + ".rst"))
        for command, sub in set(re.findall(r"\b(file|string|list|cmake_path)\(\s*([A-Z_]+)", text)):
            uses[f"{command}({sub})"] = entry_added(sub_docs[command], rf"\s*{command}\({sub}[\s)]")
        for tool in set(re.findall(r"(?:^|\s)-E\s+([a-z_]+)", text)):
            uses[f"cmake -E {tool}"] = entry_added(cmake_1, rf"\.\. option:: {tool}\b")
        for genex in set(re.findall(r"\$<([A-Z_]+)[:>]", text)):
            uses[f"$<{genex}>"] = entry_added(genex_7, rf"\.\. genex:: \$<{genex}[:>]")
        for variable in set(re.findall(r"\b((?:CMAKE|PROJECT)_[A-Z0-9_]+)\b", text)):
            uses[variable] = page_added(os.path.join(help_dir, "variable", variable + ".rst"))
        newer = sorted(f"{what} (CMake {'.'.join(map(str, added))})" for what, added in uses.items()
                       if added and added > minimum)
        for what in newer:
            print(f"{path}: {what} is newer than CMake {sys.argv[1]}")
        failed = failed or bool(newer)
    print(f"{len(files)} CMake files checked against CMake {sys.argv[1]}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
