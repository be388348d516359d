#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
# Checks the include directions against docs/code-overview.md's tables: a layer's headers and
# sources include only its own headers and those of the layers it depends on (transitively); every
# dependency is listed above the layer that has it (the order of the tables, not only the closure:
# an arrow up the table is an error even when the closure allows it); no machine feature (the rows
# of "The features: rooms beside the hub") is included by the hub, the interpreter or the real-time
# core; and the servo tick's public header does not pull <string> or <vector> into the real-time core.
"""usage: include_directions.py SOURCE_DIR"""
import re
import sys
from pathlib import Path

TICK_HEADERS = ["control/servo.hpp", "control/tickable.hpp", "control/channels.hpp"]
BANNED_IN_TICK = {"string", "vector", "map", "memory", "functional", "thread", "mutex"}
# What must never include a machine feature: the hub, the interpreter, the real-time core.
NO_FEATURES = {"controller", "gcode", "control", "traj", "motion", "machine", "hal", "core"}
FEATURES_HEADING = "## The features"


def layer_table(doc):
    """[(layer, direct dependencies, is a feature)] from the rows of the tables whose last column is
    "depends on" (other tables may name layers too), in document order."""
    rows, in_features, in_layer_table, previous = [], False, False, ""
    for line in doc.read_text().splitlines():
        if line.startswith("## "):
            in_features = line.startswith(FEATURES_HEADING)
        if line.startswith("|") and not previous.startswith("|"):  # a table's header row
            in_layer_table = line.strip().strip("|").split("|")[-1].strip() == "depends on"
        previous = line
        m = re.match(r"\|\s*`([a-z_]+)`\s*\|", line)
        if m and in_layer_table:
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            rows.append((m.group(1), set(re.findall(r"[a-z_+]+", cells[-1])), in_features))
    names = {name for name, _, _ in rows}
    return [(name, {d for d in deps if d in names}, feature) for name, deps, feature in rows]


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


def files_of(root, layer):
    for folder in (root / "include/opencnc" / layer, root / "src" / layer):
        yield from sorted(folder.rglob("*.[ch]pp")) if folder.is_dir() else []


def check_order(rows):
    """Every dependency is listed above the layer that has it."""
    errors, seen = [], set()
    for name, deps, _ in rows:
        for d in sorted(deps - seen):
            errors.append(f"docs/code-overview.md: '{name}' depends on '{d}', which is listed below it "
                          f"(dependencies point down the tables)")
        seen.add(name)
    return errors


def check_layers(root, deps, features):
    errors = []
    for layer in deps:
        allowed = closure(deps, layer) | {layer}
        for f in files_of(root, layer):
            for inc in includes(f):
                m = re.match(r"opencnc/([a-z_]+)/", inc)
                if not m:
                    continue
                if m.group(1) in features and layer in NO_FEATURES:
                    errors.append(f"{f.relative_to(root)}: includes {inc}: the feature '{m.group(1)}' is "
                                  f"included by '{layer}', which no feature may be")
                elif m.group(1) not in allowed:
                    errors.append(f"{f.relative_to(root)}: includes {inc}, but layer '{layer}' "
                                  f"depends only on {sorted(allowed - {layer}) or 'nothing'}")
    return errors


def check_no_feature_below(deps, features):
    """The table itself gives no feature to the hub, the interpreter or the real-time core."""
    return [f"docs/code-overview.md: '{layer}' may not depend on the feature '{d}'"
            for layer in sorted(NO_FEATURES & deps.keys()) for d in sorted(closure(deps, layer) & features)]


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
    rows = layer_table(root / "docs/code-overview.md")
    if len(rows) < 5:
        print("docs/code-overview.md: the layer table was not found")
        return 1
    deps = {name: d for name, d, _ in rows}
    features = {name for name, _, feature in rows if feature}
    if not features:
        print(f"docs/code-overview.md: no feature rows under '{FEATURES_HEADING}'")
        return 1
    errors = check_order(rows) + check_no_feature_below(deps, features) + check_layers(root, deps, features)
    tick_errors, headers = check_tick(root)
    for e in errors + tick_errors:
        print(e)
    if errors or tick_errors:
        return 1
    print(f"{len(deps) - len(features)} layers and {len(features)} features follow docs/code-overview.md in "
          f"order; no feature below the hub; the tick's {headers} headers pull no "
          f"<{'>, <'.join(sorted(BANNED_IN_TICK))}>")
    return 0


if __name__ == "__main__":
    sys.exit(main())
