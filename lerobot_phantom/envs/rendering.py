"""Offscreen OpenGL backend selection for MuJoCo.

MuJoCo reads ``MUJOCO_GL`` once, when ``mujoco`` is first imported, and PyOpenGL fixes its platform on its first
import too, so the backend cannot be switched inside a running process. We therefore choose it *before* importing
mujoco: a user-set ``MUJOCO_GL`` always wins; otherwise EGL is probed in a short subprocess, then OSMesa, and the
first one that can create a context is exported (so vector-env workers and subprocesses inherit it).
"""

from __future__ import annotations

import os
import subprocess
import sys

BACKENDS = ("egl", "osmesa")

_PROBE = "import mujoco; ctx = mujoco.GLContext(8, 8); ctx.make_current(); ctx.free()"


class RenderingBackendError(RuntimeError):
    pass


def probe_backend(backend: str, timeout_s: float = 60.0) -> tuple[bool, str]:
    """Try to create an offscreen GL context with ``backend`` in a fresh interpreter; returns (ok, stderr)."""
    env = {**os.environ, "MUJOCO_GL": backend}
    env.pop("PYOPENGL_PLATFORM", None)
    result = subprocess.run(
        [sys.executable, "-c", _PROBE],
        env=env,
        capture_output=True,
        text=True,
        timeout=timeout_s,
        check=False,
    )
    return result.returncode == 0, result.stderr.strip()


def select_gl_backend() -> str:
    """Export a working ``MUJOCO_GL`` (egl, else osmesa) unless the user already set one; return the choice.

    Also defaults ``LP_NUM_THREADS=0`` (Mesa llvmpipe renders in the calling thread): llvmpipe's worker threads do
    not survive ``fork``, so without this an ``AsyncVectorEnv`` forked after the parent rendered deadlocks in its
    children; at 96x96 the worker threads bring nothing anyway.
    """
    os.environ.setdefault("LP_NUM_THREADS", "0")
    chosen = os.environ.get("MUJOCO_GL")
    if chosen:
        return chosen
    if "mujoco" in sys.modules:
        # Too late to influence mujoco's choice; report what it will use rather than pretending.
        return os.environ.get("MUJOCO_GL", "")
    errors = {}
    for backend in BACKENDS:
        ok, stderr = probe_backend(backend)
        if ok:
            os.environ["MUJOCO_GL"] = backend
            return backend
        errors[backend] = stderr.splitlines()[-1] if stderr else "unknown error"
    details = "; ".join(f"{name}: {err}" for name, err in errors.items())
    raise RenderingBackendError(
        "No offscreen OpenGL backend works for MuJoCo (tried MUJOCO_GL=egl and MUJOCO_GL=osmesa). "
        "Install one of them, e.g. `apt-get install -y libegl1` or `apt-get install -y libosmesa6`, "
        f"or set MUJOCO_GL yourself. Details: {details}"
    )
