#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# Checks the include directions against docs/code-overview.md's layer table: a layer's headers and
# sources include only its own headers and those of the layers it depends on (transitively), and
# the servo tick's public header does not pull <string> or <vector> into the real-time core.
"""usage: include_directions.py SOURCE_DIR"""
import re
import sys
from pathlib import Path

TICK_HEADERS = ["control/servo.hpp", "control/tickable.hpp", "control/channels.hpp"]
BANNED_IN_TICK = {"string", "vector", "map", "memory", "functional", "thread", "mutex"}


def layer_table(doc):
    """{layer: set of direct dependencies} from the table's rows (`layer` | rt | holds | deps)."""
    deps = {}
    for line in doc.read_text().splitlines():
        m = re.match(r"\|\s*`([a-z_]+)`\s*\|", line)
        if m:
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            deps[m.group(1)] = set(re.findall(r"[a-z_+]+", cells[-1]))
    return {k: {d for d in v if d in deps} for k, v in deps.items()}


def closure(deps, layer):
    seen, todo = set(), [layer]
    while todo:
        for d in deps.get(todo.pop(), ()):
            if d not in seen:
                seen.add(d)
                todo.append(d)
    return seen


def includes(path):
    if not path.is_file():
        return []
    return re.findall(r'^#include [<"]([^>"]+)[>"]', path.read_text(), re.M)


def check_layers(root, deps):
    errors = []
    for layer in deps:
        allowed = closure(deps, layer) | {layer}
        for folder in (root / "include/opencnc" / layer, root / "src" / layer):
            for f in sorted(folder.rglob("*.[ch]pp")) if folder.is_dir() else []:
                for inc in includes(f):
                    m = re.match(r"opencnc/([a-z_]+)/", inc)
                    if m and m.group(1) not in allowed:
                        errors.append(f"{f.relative_to(root)}: includes {inc}, but layer '{layer}' "
                                      f"depends only on {sorted(allowed - {layer}) or 'nothing'}")
    return errors


def check_tick(root):
    errors, seen, todo = [], set(), list(TICK_HEADERS)
    while todo:
        h = todo.pop()
        if h in seen:
            continue
        seen.add(h)
        for inc in includes(root / "include/opencnc" / h):
            if inc.startswith("opencnc/"):
                todo.append(inc[len("opencnc/"):])
            elif inc in BANNED_IN_TICK:
                errors.append(f"include/opencnc/{h}: <{inc}> reaches the tick's public headers")
    return errors, len(seen)


def main():
    if len(sys.argv) != 2 or sys.argv[1].startswith("-"):
        asked = sys.argv[1:2] in (["--help"], ["-h"])
        print(__doc__, file=sys.stdout if asked else sys.stderr)
        return 0 if asked else 2
    root = Path(sys.argv[1])
    deps = layer_table(root / "docs/code-overview.md")
    if len(deps) < 5:
        print("docs/code-overview.md: the layer table was not found")
        return 1
    errors = check_layers(root, deps)
    tick_errors, headers = check_tick(root)
    for e in errors + tick_errors:
        print(e)
    if errors or tick_errors:
        return 1
    print(f"{len(deps)} layers follow docs/code-overview.md; the tick's {headers} headers pull no "
          f"<{'>, <'.join(sorted(BANNED_IN_TICK))}>")
    return 0


if __name__ == "__main__":
    sys.exit(main())
