import os
import sys

import pytest

from lerobot_phantom.envs import rendering


def test_user_choice_wins_without_probing(monkeypatch):
    monkeypatch.setenv("MUJOCO_GL", "osmesa")

    def must_not_probe(backend, timeout_s=60.0):
        raise AssertionError("probed although MUJOCO_GL was set")

    monkeypatch.setattr(rendering, "probe_backend", must_not_probe)
    assert rendering.select_gl_backend() == "osmesa"


def test_falls_back_to_osmesa_then_fails_with_install_hint(monkeypatch):
    monkeypatch.delenv("MUJOCO_GL", raising=False)
    monkeypatch.delitem(sys.modules, "mujoco", raising=False)
    probed = []

    def egl_broken(backend, timeout_s=60.0):
        probed.append(backend)
        return backend == "osmesa", "" if backend == "osmesa" else "EGL: no display"

    monkeypatch.setattr(rendering, "probe_backend", egl_broken)
    assert rendering.select_gl_backend() == "osmesa"
    assert probed == ["egl", "osmesa"]
    assert os.environ["MUJOCO_GL"] == "osmesa"

    monkeypatch.delenv("MUJOCO_GL")
    monkeypatch.setattr(
        rendering, "probe_backend", lambda backend, timeout_s=60.0: (False, f"{backend} missing")
    )
    with pytest.raises(rendering.RenderingBackendError, match=r"libegl1.*libosmesa6.*egl missing"):
        rendering.select_gl_backend()


def test_the_selected_backend_really_renders():
    backend = rendering.select_gl_backend()  # mujoco is imported by now; this reports its backend
    ok, stderr = rendering.probe_backend(backend)
    assert ok, stderr
