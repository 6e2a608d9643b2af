"""Per case, from ``tone_position_cases.py``'s output: draws, passes, draws where ``sensor_gamma`` was checked and kept
(with the range of the whole frame's departure from 1 over the halves' mean), and draws where the check withdrew it.

    python docs/bench/session60/tone_position_summary.py docs/bench/session60/tone_position_cases.txt
"""

import re
import sys
from pathlib import Path


def main() -> None:
    block, rows = "", {}
    for line in Path(sys.argv[1]).read_text().splitlines():
        if line.startswith("# "):
            block = (
                "before the check" if "before the check" in line else ("fresh" if "fresh" in line else "six")
            )
            continue
        case = line.split()[0]
        entry = rows.setdefault((block, case), {"draws": 0, "pass": 0, "ratios": [], "withdrawn": []})
        entry["draws"] += 1
        entry["pass"] += " pass " in line
        ratio = re.search(r"ratio (-?[\d.]+)", line)
        if ratio:
            entry["ratios"].append(float(ratio.group(1)))
        withdrawn = re.search(
            r"withdrawn \[sensor_gamma: .*?\((\d\.\d+)\) and on the rest \((\d\.\d+)\)", line
        )
        if withdrawn:
            entry["withdrawn"].append(line.split()[1])
    for (block, case), e in rows.items():
        kept = f"{min(e['ratios']):.2f}-{max(e['ratios']):.2f}" if e["ratios"] else "-"
        print(
            f"{block:16s} {case:28s} draws {e['draws']} pass {e['pass']} checked and kept {len(e['ratios'])} "
            f"({kept}) withdrawn {len(e['withdrawn'])} {e['withdrawn']}"
        )
    kept = [r for (block, _), e in rows.items() if block != "before the check" for r in e["ratios"]]
    print(f"all draws with the check: gamma checked and kept on {len(kept)}, {min(kept):.2f}-{max(kept):.2f}")


if __name__ == "__main__":
    main()
