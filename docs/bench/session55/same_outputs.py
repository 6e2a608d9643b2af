"""Whether two calibration outputs agree in everything but where their input lay.

    python same_outputs.py OUT_A OUT_B

report.json without ``input.path``, calibrated.json without ``source`` (the input's path and kind), and the lines of
report.md other than its "Input:" line.
"""

import json
import sys
from pathlib import Path


def main() -> None:
    first, second = Path(sys.argv[1]), Path(sys.argv[2])
    for name, where in (("report.json", ("input", "path")), ("calibrated.json", ("source",))):
        outputs = [json.loads((folder / name).read_text()) for folder in (first, second)]
        for output in outputs:
            *parents, key = where
            for parent in parents:
                output = output[parent]
            output.pop(key)
        print(name, "identical" if outputs[0] == outputs[1] else "DIFFERENT")
    lines = [(folder / "report.md").read_text().splitlines() for folder in (first, second)]
    differing = sum(a != b and "Input:" not in a for a, b in zip(*lines, strict=False)) + abs(
        len(lines[0]) - len(lines[1])
    )
    print(f"report.md lines differing: {differing} of {len(lines[0])}")


if __name__ == "__main__":
    main()
