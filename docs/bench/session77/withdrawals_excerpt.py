"""What a calibration's passes withdrew and why, and its last pass's identification with each effect's ratio of the
model without it: an excerpt of one report.json. Usage: ``python docs/bench/session77/withdrawals_excerpt.py
REPORT_JSON...``."""

import json
import sys
from pathlib import Path


def main() -> None:
    for path in sys.argv[1:]:
        report = json.loads(Path(path).read_text())
        selection = report["selection"]
        print(path)
        for earlier in selection.get("earlier_passes", []):
            print(f"  pass {earlier['pass']} selected {earlier['selected']}, withdrew {earlier['withdrawn']}")
            for step in earlier["steps"]:
                print(f"    step {step['effects']}: {step['validation_error']:.3f}")
        for withdrawal in selection.get("withdrawn", []):
            print(
                f"  withdrawn {withdrawal['effect']} (pass {withdrawal['pass']}): {'; '.join(withdrawal['reasons'])}"
            )
        print("  last pass's steps:")
        for step in selection["steps"]:
            print(f"    step {step['effects']}: {step['validation_error']:.3f}")
        for result in report["identification"]:
            without = result.get("ratio_without")
            shown = (
                f"{without['estimate']:.4f} [{without['low']:.4f}, {without['high']:.4f}]" if without else "-"
            )
            print(
                f"  {result['effect']}: {result['status']}; without it {shown}; {'; '.join(result['reasons'])}"
            )
        print(
            f"  written: {report['extended']['effects']}, held-out {report['extended']['heldout_rmse']:.3f}"
        )


if __name__ == "__main__":
    main()
