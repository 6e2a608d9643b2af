"""Command-line conveniences shared by the lerobot-phantom CLIs (draccus entry points)."""

from __future__ import annotations

from collections.abc import Sequence


def normalize_argv(argv: Sequence[str], bare_flags: Sequence[str]) -> list[str]:
    """Accept dashed names (``--repo-id`` for ``--repo_id``) and bare boolean flags (``--resume``): draccus wants
    ``--repo_id=...`` and ``--resume=true``."""
    out: list[str] = []
    for position, arg in enumerate(argv):
        if not arg.startswith("--"):
            out.append(arg)
            continue
        name, sep, value = arg[2:].partition("=")
        name = name.replace("-", "_")
        following = argv[position + 1] if position + 1 < len(argv) else None
        if name in bare_flags and not sep and (following is None or following.startswith("--")):
            out.append(f"--{name}=true")
        else:
            out.append(f"--{name}{sep}{value}")
    return out
