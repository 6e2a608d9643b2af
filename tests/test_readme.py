"""Every snippet in README.md runs as a test (issue 13, item 6).

How each fenced block of the README is treated, in order:

* ``python`` blocks are executed (a fresh interpreter, in the scratch directory);
* ``bash`` / ``sh`` / ``shell`` / ``console`` blocks are run by ``bash -e -o pipefail`` in the scratch directory,
  in README order: each command's inputs must have been created by an earlier block (or be the repository's
  ``configs/``, linked into the scratch directory), never by hand;
* ``json`` blocks must parse (a fragment such as ``"image_transforms": {...}`` is read inside braces), and an
  ``image_transforms`` object must build through LeRobot's ``ImageTransforms`` after ``lerobot_phantom.register()``;
* a shell block that runs ``scripts/setup.sh`` (system packages, ``pip install``) or pytest (the suite would run
  this test again) is never run by a test: it must be skipped as covered by ``.ci/run``, which runs both;
* any other block, and any block the test cannot run verbatim within CI's budget, carries an annotation: an HTML
  comment (invisible on GitHub) on the line right before the opening fence. The forms:

  ``<!-- readme-test: skip; REASON; covered by PATH[::TEST] -->``
      not run here; PATH (``tests/...`` or ``.ci/run``) must exist, and TEST, if named, must be defined in it.
      A block covered by ``.ci/run`` must be, verbatim, the command between ``.ci/run``'s markers.
  ``<!-- readme-test: replace `OLD` with `NEW`; REASON -->``
      run with OLD replaced by NEW (OLD must occur in the block); several may be stacked on consecutive lines.
  ``<!-- readme-test: not code; REASON -->``
      an illustration (directory tree, pseudo-command side by side), not meant to be run.

A block that is neither runnable nor annotated, or a malformed annotation, fails
``test_every_block_is_run_or_annotated``. Each runnable block is its own test case
(``test_readme_block[NN-LANG-LLINE]``); all blocks are run once, in order, by a module fixture.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
README = REPO / "README.md"
CI_RUN = REPO / ".ci" / "run"
SHELL_LANGUAGES = {"bash", "sh", "shell", "console"}
BLOCK_TIMEOUT_S = 900  # a hang guard, not a time limit: a block that cannot run quickly gets an annotation

FENCE = re.compile(r"^(?P<indent> {0,3})(?P<fence>```+|~~~+)(?P<info>[^`]*)$")
ANNOTATION = re.compile(r"^\s*<!--\s*readme-test:\s*(?P<body>.*?)\s*-->\s*$")
REPLACE = re.compile(r"^replace `(?P<old>[^`]+)` with `(?P<new>[^`]*)`;\s*(?P<reason>\S.*)$")
SKIP = re.compile(r"^skip;\s*(?P<reason>[^;]*\S)\s*;\s*covered by\s+(?P<path>[^:\s]+)(?:::(?P<test>\w+))?$")
NOT_CODE = re.compile(r"^not code;\s*(?P<reason>\S.*)$")


class ReadmeError(ValueError):
    """A README block the harness cannot account for (unannotated, or a malformed annotation)."""


@dataclass(frozen=True)
class Block:
    index: int
    line: int  # 1-based line of the opening fence
    language: str
    text: str
    annotations: tuple[str, ...] = ()

    @property
    def case_id(self) -> str:
        return f"{self.index:02d}-{self.language or 'plain'}-L{self.line}"


@dataclass(frozen=True)
class Plan:
    """What the harness does with a block: ``kind`` in run-python / run-shell / check-json / skip / not-code."""

    kind: str
    text: str = ""
    reason: str = ""
    covered_by: str = ""
    replacements: list[tuple[str, str]] = field(default_factory=list)


def parse_blocks(markdown: str) -> list[Block]:
    """The fenced blocks of ``markdown``, each with the annotation lines right above its opening fence."""
    lines = markdown.splitlines()
    blocks: list[Block] = []
    position = 0
    while position < len(lines):
        opening = FENCE.match(lines[position])
        if opening is None:
            position += 1
            continue
        fence, language = opening["fence"], opening["info"].strip().split(" ")[0].lower()
        end = position + 1
        while end < len(lines) and not lines[end].strip().startswith(fence[0] * len(fence)):
            end += 1
        if end == len(lines):
            raise ReadmeError(f"README line {position + 1}: code block never closed")
        annotations = []
        above = position - 1
        while above >= 0 and ANNOTATION.match(lines[above]):
            annotations.insert(0, ANNOTATION.match(lines[above])["body"])
            above -= 1
        blocks.append(
            Block(
                len(blocks),
                position + 1,
                language,
                "\n".join(lines[position + 1 : end]) + "\n",
                tuple(annotations),
            )
        )
        position = end + 1
    return blocks


def plan_block(block: Block, repo: Path = REPO) -> Plan:
    """How ``block`` is tested; raises ``ReadmeError`` naming the block and the accepted annotations otherwise."""
    where = f"README block {block.case_id} (line {block.line})"
    replacements: list[tuple[str, str]] = []
    for body in block.annotations:
        if match := SKIP.match(body):
            path = repo / match["path"]
            if not path.exists():
                raise ReadmeError(f"{where}: 'covered by {match['path']}' names no file of the repository")
            if match["test"] and not re.search(rf"^\s*def {match['test']}\(", path.read_text(), re.M):
                raise ReadmeError(f"{where}: {match['path']} defines no test {match['test']!r}")
            if len(block.annotations) > 1:
                raise ReadmeError(f"{where}: a skipped block takes no other annotation")
            return Plan(
                "skip",
                block.text,
                match["reason"],
                match["path"] + (f"::{match['test']}" if match["test"] else ""),
            )
        if match := NOT_CODE.match(body):
            if len(block.annotations) > 1:
                raise ReadmeError(f"{where}: a 'not code' block takes no other annotation")
            return Plan("not-code", block.text, match["reason"])
        if match := REPLACE.match(body):
            if match["old"] not in block.text:
                raise ReadmeError(f"{where}: 'replace `{match['old']}`' but the block does not contain it")
            replacements.append((match["old"], match["new"]))
            continue
        raise ReadmeError(
            f"{where}: unknown annotation {body!r}; use 'skip; REASON; covered by PATH[::TEST]', "
            "'replace `OLD` with `NEW`; REASON' or 'not code; REASON'"
        )
    text = block.text
    for old, new in replacements:
        text = text.replace(old, new)
    if block.language == "python":
        return Plan("run-python", text, replacements=replacements)
    if block.language in SHELL_LANGUAGES:
        if "scripts/setup.sh" in text or re.search(r"\bpytest\b", text):
            raise ReadmeError(
                f"{where}: runs scripts/setup.sh (system packages, pip install) or the test suite (which runs this "
                "test): never from a test; annotate it 'skip; REASON; covered by .ci/run' (CI runs both itself)"
            )
        return Plan("run-shell", text, replacements=replacements)
    if block.language == "json":
        return Plan("check-json", text, replacements=replacements)
    raise ReadmeError(
        f"{where}: a {block.language or 'plain'!r} block is neither run nor annotated; put "
        "'<!-- readme-test: not code; REASON -->' (or a skip) on the line above its opening fence"
    )


def readme_blocks() -> list[Block]:
    return parse_blocks(README.read_text())


# -- running -----------------------------------------------------------------------------------------------
def check_json(text: str) -> None:
    try:
        data = json.loads(text)
    except json.JSONDecodeError:
        data = json.loads("{" + text + "}")  # a fragment of a config, as the README shows them
    if "image_transforms" in data:
        import draccus
        import torch
        from lerobot.datasets.transforms import ImageTransforms, ImageTransformsConfig

        import lerobot_phantom

        lerobot_phantom.register()
        transforms = ImageTransforms(draccus.decode(ImageTransformsConfig, data["image_transforms"]))
        image = torch.rand(3, 64, 64, generator=torch.Generator().manual_seed(0))
        assert transforms(image).shape == image.shape


def run_block(plan: Plan, block: Block, scratch: Path) -> tuple[bool, str]:
    """Run one planned block in ``scratch``; returns (ok, what went wrong)."""
    if plan.kind == "check-json":
        try:
            check_json(plan.text)
        except Exception as err:  # reported as the block's failure, with its cause
            return False, f"{type(err).__name__}: {err}"
        return True, ""
    if plan.kind == "run-python":
        script = scratch / f"readme_block_{block.index:02d}.py"
        script.write_text(plan.text)
        argv = [sys.executable, script.name]
    else:
        argv = ["bash", "-e", "-o", "pipefail", "-c", plan.text]
    env = {
        **os.environ,
        "HF_HUB_OFFLINE": "1",
        "OMP_NUM_THREADS": os.environ.get("OMP_NUM_THREADS", "1"),
        "HF_LEROBOT_HOME": str(scratch / ".lerobot_home"),
        "MPLBACKEND": "Agg",
    }
    try:
        result = subprocess.run(
            argv, cwd=scratch, env=env, capture_output=True, text=True, timeout=BLOCK_TIMEOUT_S
        )
    except subprocess.TimeoutExpired:
        return False, f"still running after {BLOCK_TIMEOUT_S} s: annotate it (replace or skip)"
    if result.returncode != 0:
        return False, f"exit status {result.returncode}\n{(result.stdout + result.stderr)[-3000:]}"
    return True, ""


@pytest.fixture(scope="module")
def readme_results(tmp_path_factory) -> dict[int, tuple[bool, str]]:
    """Every runnable block, run once in README order in one scratch directory."""
    scratch = tmp_path_factory.mktemp("readme")
    (scratch / "configs").symlink_to(REPO / "configs", target_is_directory=True)
    results = {}
    for block in readme_blocks():
        try:
            plan = plan_block(block)
        except ReadmeError as err:
            results[block.index] = (False, str(err))
            continue
        if plan.kind.startswith(("run-", "check-")):
            results[block.index] = run_block(plan, block, scratch)
    return results


# -- the README ----------------------------------------------------------------------------------------------
def test_every_block_is_run_or_annotated():
    problems = []
    for block in readme_blocks():
        try:
            plan_block(block)
        except ReadmeError as err:
            problems.append(str(err))
    assert not problems, "\n".join(problems)


RUNNABLE = [b for b in readme_blocks() if b.language in {"python", "json", *SHELL_LANGUAGES}]


@pytest.mark.slow
@pytest.mark.parametrize("block", RUNNABLE, ids=[b.case_id for b in RUNNABLE])
def test_readme_block(block, readme_results):
    try:
        plan = plan_block(block)
    except ReadmeError as err:
        pytest.fail(str(err))
    if plan.kind == "skip":
        pytest.skip(f"annotated in README.md: {plan.reason} (covered by {plan.covered_by})")
    ok, problem = readme_results[block.index]
    assert ok, f"README line {block.line} ({block.language}):\n{plan.text}\n{problem}"


def ci_test_command() -> str:
    text = CI_RUN.read_text()
    match = re.search(r"# --- the README's test command, verbatim ---\n(?P<command>.*?)\n", text)
    assert match, f"{CI_RUN} has no '# --- the README's test command, verbatim ---' marker"
    return match["command"].strip()


def test_ci_runs_exactly_the_readme_test_command():
    covered = [plan_block(b) for b in readme_blocks() if any(".ci/run" in a for a in b.annotations)]
    assert covered, "no README block is annotated 'covered by .ci/run' (the test command CI runs)"
    commands = [line for plan in covered for line in plan.text.splitlines() if "pytest" in line]
    assert ci_test_command() in [c.strip() for c in commands]


def test_ci_fails_when_pytest_collects_no_test(tmp_path):
    (tmp_path / ".ci").mkdir()
    (tmp_path / ".ci" / "run").write_text(CI_RUN.read_text())
    (tmp_path / "scripts").mkdir()
    (tmp_path / "scripts" / "setup.sh").write_text("exit 0\n")  # CI's install step, stubbed
    (tmp_path / "pyproject.toml").write_text("")
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}

    def ci():
        return subprocess.run(["bash", ".ci/run"], cwd=tmp_path, capture_output=True, text=True, env=env)

    nothing = ci()
    assert nothing.returncode != 0 and "collected no tests" in nothing.stdout
    (tmp_path / "test_one.py").write_text("def test_one():\n    assert True\n")
    assert ci().returncode == 0
    (tmp_path / "test_one.py").write_text("def test_one():\n    assert False\n")
    assert ci().returncode == 1


# -- the harness itself -------------------------------------------------------------------------------------
def _plan(markdown: str) -> Plan:
    (block,) = parse_blocks(markdown)
    return plan_block(block)


def test_unannotated_plain_block_is_an_error():
    with pytest.raises(ReadmeError, match="neither run nor annotated"):
        _plan("text\n\n```text\nlerobot-train --policy.type=pi0\n```\n")


def test_annotations_are_read_from_the_lines_right_above_the_fence():
    plan = _plan("<!-- readme-test: not code; a directory tree -->\n```\nlerobot_phantom/\n```\n")
    assert plan.kind == "not-code" and plan.reason == "a directory tree"
    markdown = (
        "<!-- readme-test: replace `--episodes 100` with `--episodes 2`; CI budget -->\n"
        "<!-- readme-test: replace ` [--video]` with ``; optional flag -->\n"
        "```bash\nlerobot-phantom-collect --episodes 100 [--video]\n```\n"
    )
    plan = _plan(markdown)
    assert plan.kind == "run-shell" and plan.text == "lerobot-phantom-collect --episodes 2\n"
    with pytest.raises(ReadmeError, match="neither run nor annotated"):  # a blank line breaks the link
        _plan("<!-- readme-test: not code; tree -->\n\n```\nx\n```\n")


def test_skip_needs_a_reason_and_an_existing_covering_test():
    covered = "<!-- readme-test: skip; the 15-minute demo; covered by tests/test_readme.py::{} -->\n```bash\nx\n```\n"
    plan = _plan(covered.format("test_skip_needs_a_reason_and_an_existing_covering_test"))
    assert plan.kind == "skip" and plan.reason == "the 15-minute demo"
    with pytest.raises(ReadmeError, match="defines no test"):
        _plan(covered.format("test_that_does_not_exist"))
    with pytest.raises(ReadmeError, match="names no file"):
        _plan("<!-- readme-test: skip; slow; covered by tests/no_such_test.py -->\n```bash\nx\n```\n")
    with pytest.raises(ReadmeError, match="unknown annotation"):
        _plan("<!-- readme-test: skip; covered by tests/test_readme.py -->\n```bash\nx\n```\n")


def test_setup_and_the_test_suite_are_never_run_by_the_harness():
    with pytest.raises(ReadmeError, match="never from a test"):
        _plan("```bash\nbash scripts/setup.sh && lerobot-phantom-demo --out outputs/demo\n```\n")
    with pytest.raises(ReadmeError, match="never from a test"):
        _plan("```bash\nHF_HUB_OFFLINE=1 python3 -m pytest -q\n```\n")


def test_replace_must_match_the_block():
    with pytest.raises(ReadmeError, match="does not contain it"):
        _plan(
            "<!-- readme-test: replace `--steps 9` with `--steps 1`; budget -->\n```bash\nx --steps 2\n```\n"
        )


def test_json_fragments_are_read_inside_braces():
    check_json('"a": {"b": 1}')
    with pytest.raises(json.JSONDecodeError):
        check_json('"a": {"b": 1')
