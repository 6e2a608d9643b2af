"""The largest relative change of one run's fitted values, and of their interval ends, between two
``calibration_shared_data.py`` outputs (``compare_shared_data.py`` reports the largest change over every number).

Usage: python docs/bench/session83/fitted_value_shift.py OLD.json NEW.json RUN"""

import json
import sys
from pathlib import Path


def main(old_path: str, new_path: str, run: str) -> None:
    old, new = (json.loads(Path(p).read_text())["runs"][run] for p in (old_path, new_path))
    values = max(
        (abs(new["extended_params"][k] - v) / abs(v), k) for k, v in old["extended_params"].items() if v
    )
    ends = max(
        (abs(new["extended_param_intervals"][k][end] - v[end]) / abs(v[end]), f"{k}/{end}")
        for k, v in old["extended_param_intervals"].items()
        for end in ("low", "high")
        if v[end]
    )
    print(
        f"{run}: fitted values {values[0]:.2e} relative at most ({values[1]}); interval ends {ends[0]:.2e} ({ends[1]})"
    )


if __name__ == "__main__":
    main(*sys.argv[1:4])
