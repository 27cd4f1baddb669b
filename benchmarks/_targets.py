"""Read benchmark records (JSON lines) on standard input, echo them, and exit 1 if a record
misses its target.

A target that starts with a comparison (``<= 0.1``, ``>= 1e7``, ``< 0.020 s for ...``) is
checked against the record's value; any other target (``~5000``, ``baseline``, empty) only
describes the value.
"""

from __future__ import annotations

import json
import operator
import re
import sys

#: Comparisons a target may open with, longest first.
COMPARE = {"<=": operator.le, ">=": operator.ge, "<": operator.lt, ">": operator.gt}
TARGET = re.compile(r"^\s*(<=|>=|<|>)\s*([-+]?[0-9.]+(?:[eE][-+]?[0-9]+)?)")


def missed(record: dict) -> bool:
    """Whether ``record``'s value misses its target (False for a descriptive target)."""
    match = TARGET.match(str(record.get("target", "")))
    if match is None:
        return False
    return not COMPARE[match.group(1)](float(record["value"]), float(match.group(2)))


def main() -> int:
    misses = []
    for line in sys.stdin:
        print(line, end="")
        try:
            record = json.loads(line)
        except json.JSONDecodeError:
            continue
        if isinstance(record, dict) and missed(record):
            misses.append(f"{record['benchmark']} = {record['value']} {record['unit']} "
                          f"(target {record['target']})")  # fmt: skip
    for miss in misses:
        print(f"bench: missed: {miss}", file=sys.stderr)
    return 1 if misses else 0


if __name__ == "__main__":
    sys.exit(main())
