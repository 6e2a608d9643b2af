"""Rendering shared by the report's tables: attack names with the paper's abbreviations, condition labels, and a
table written as Markdown, CSV and LaTeX with notes saying what its cells mean."""

import csv
import io
from dataclasses import dataclass

from lerobot_phantom.eval.results import CLEAN

ABBREVIATIONS = {
    CLEAN: "Clean",
    "laser_blinding": "LB",
    "light_projection": "LP",
    "laser_color_strip": "LCS",
    "em_color_strip": "ECS",
    "em_truncation": "ET",
    "ultrasound_blur": "UB",
    "voice_dos": "VD",
    "voice_spoofing": "VS",
}
ATTACK_TITLES = {
    CLEAN: "Clean",
    "laser_blinding": "Laser blinding",
    "light_projection": "Light projection",
    "laser_color_strip": "Laser color strip",
    "em_color_strip": "EM color strip",
    "em_truncation": "EM truncation",
    "ultrasound_blur": "Ultrasound blur",
    "voice_dos": "Voice DoS",
    "voice_spoofing": "Voice spoofing",
}


def attack_title(attack: str) -> str:
    """``Laser blinding (LB)``: the attack spelt out with the paper's abbreviation; ``Clean`` for the control."""
    if attack == CLEAN:
        return ATTACK_TITLES[CLEAN]
    if attack not in ATTACK_TITLES:
        return attack
    return f"{ATTACK_TITLES[attack]} ({ABBREVIATIONS[attack]})"


def condition_label(condition: str, latex: bool = False) -> str:
    """``Laser blinding (LB), strong``; LaTeX-escaped with the clean control in bold when ``latex``."""
    attack, _, level = condition.partition("@")
    name = attack_title(attack) + (f", {level}" if level else "")
    if latex:
        name = latex_escape(name)
        return f"\\textbf{{{name}}}" if condition == CLEAN else name
    return name


def percent(value: float) -> str:
    return f"{100.0 * value:.1f}"


@dataclass
class Table:
    """A table with one header row per column group (labels) and one per column (suites)."""

    groups: list[tuple[str, int]]  # (group label, number of columns)
    columns: list[str]
    rows: list[tuple[str, list[str]]]  # (condition, cells)
    corner: str = "Attack"
    # What the cells mean (units, symbols); printed under the Markdown and LaTeX tables.
    notes: tuple[str, ...] = ()
    # Unit of the cells, named in the CSV header (CSV has no room for notes).
    unit: str = "TSR %"

    @property
    def column_groups(self) -> list[str]:
        """The group label of every column."""
        return [label for label, count in self.groups for _ in range(count)]

    def markdown(self) -> str:
        headers = [
            f"{group} {column}".strip()
            for group, column in zip(self.column_groups, self.columns, strict=True)
        ]
        lines = [
            "| " + " | ".join([self.corner, *headers]) + " |",
            "|" + "|".join(["---"] + ["---:"] * len(headers)) + "|",
        ]
        lines += ["| " + " | ".join([condition_label(c), *cells]) + " |" for c, cells in self.rows]
        for note in self.notes:
            lines += ["", note]
        return "\n".join(lines) + "\n"

    def csv(self) -> str:
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        if any(self.column_groups):
            writer.writerow(["", *self.column_groups])
        writer.writerow([f"condition [{self.unit}]", *self.columns])
        for condition, cells in self.rows:
            writer.writerow([condition, *cells])
        return buffer.getvalue()

    def latex(self) -> str:
        n = len(self.columns)
        lines = ["\\begin{tabular}{l" + "c" * n + "}", "\\toprule"]
        if any(label for label, _ in self.groups):
            spans, start = [], 2
            cells = []
            for label, count in self.groups:
                cells.append(f"\\multicolumn{{{count}}}{{c}}{{\\textbf{{{latex_escape(label)}}}}}")
                spans.append(f"\\cmidrule(lr){{{start}-{start + count - 1}}}")
                start += count
            lines.append(" & ".join(["", *cells]) + " \\\\")
            lines.append(" ".join(spans))
        lines.append(" & ".join([f"\\textbf{{{self.corner}}}", *map(latex_escape, self.columns)]) + " \\\\")
        lines.append("\\midrule")
        for condition, cells in self.rows:
            lines.append(" & ".join([condition_label(condition, latex=True), *cells]) + " \\\\")
            if condition == CLEAN:
                lines.append("\\midrule")
        lines.append("\\bottomrule")
        lines += [
            f"\\multicolumn{{{n + 1}}}{{l}}{{\\footnotesize {latex_escape(note)}}} \\\\"
            for note in self.notes
        ]
        lines.append("\\end{tabular}")
        return "\n".join(lines) + "\n"


def latex_escape(text: str) -> str:
    for char, escaped in (
        ("\\", "\\textbackslash{}"),
        ("_", "\\_"),
        ("%", "\\%"),
        ("&", "\\&"),
        ("#", "\\#"),
        ("<", "$<$"),
        (">", "$>$"),
    ):
        text = text.replace(char, escaped)
    return text
