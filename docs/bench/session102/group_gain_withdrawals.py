"""Which calibrations' identification withdrew an effect by session 100's group-gain test (a change of form taken in
one step with others must gain beside them), and which effects carried a ``gain_in_group`` at all, over every
report.json under the given folders (this session read the scratch runs of sessions 97-102, not in the repository).

Usage: ``python docs/bench/session102/group_gain_withdrawals.py FOLDER...``
"""

import json
import sys
from collections import Counter
from pathlib import Path

REASON = "a change of form taken in one step with"

reports, judged, withdrawals = 0, Counter(), []
for folder in sys.argv[1:]:
    for path in sorted(Path(folder).rglob("report.json")):
        report = json.loads(path.read_text())
        reports += 1
        for result in report.get("identification", []):
            if "gain_in_group" in result:
                judged[(result["effect"], result["identified"])] += 1
        for withdrawal in report.get("selection", {}).get("withdrawn", []) or []:
            if any(REASON in reason for reason in withdrawal["reasons"]):
                withdrawals.append(
                    f"{path.relative_to(folder)}: {withdrawal['effect']} (pass {withdrawal['pass']})"
                )
print(f"{reports} report.json files")
print("effects judged by the group gain in the written reports (effect, identified): count")
for key, count in sorted(judged.items()):
    print(f"  {key}: {count}")
print(f"withdrawn by the group-gain test: {len(withdrawals)}")
for line in withdrawals:
    print(f"  {line}")
