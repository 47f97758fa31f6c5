#!/usr/bin/env python3
"""The translation units of a unity-build compile database that hold the given sources.

    .ci/tidy_batches.py BUILD_DIR FILE...

BUILD_DIR was configured with CMAKE_UNITY_BUILD=ON and CMAKE_EXPORT_COMPILE_COMMANDS=ON;
each FILE is an absolute path. Prints, one per line, every compile command's file that is a
FILE or a CMake unity file including one (clang-tidy then parses the headers that the
batch's files share once). Exits 1 naming each FILE that no command compiles: run-clang-tidy
would skip it without a word.
"""
import json
import re
import sys

INCLUDE = re.compile(r'^#include "([^"]+)"$', re.MULTILINE)


def main(argv):
    if len(argv) < 3:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    wanted = set(argv[2:])
    with open(f"{argv[1]}/compile_commands.json", encoding="utf-8") as f:
        commands = json.load(f)
    units, covered = [], set()
    for command in commands:
        unit = command["file"]
        sources = {unit}
        if "/Unity/unity_" in unit:
            with open(unit, encoding="utf-8") as f:
                sources = set(INCLUDE.findall(f.read()))
        if sources & wanted and unit not in units:
            units.append(unit)
            covered |= sources & wanted
    for unit in units:
        print(unit)
    missing = sorted(wanted - covered)
    for path in missing:
        print(f"tidy_batches: no compile command for {path}", file=sys.stderr)
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
