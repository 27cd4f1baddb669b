"""Shared fixtures."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import settings

settings.register_profile("ci", max_examples=200, deadline=None, derandomize=True)
settings.register_profile("dev", max_examples=100, deadline=None)
settings.load_profile("ci")

#: Public programs written by others, beside the clone; absent in a user's clone.
SHARED_PROGRAMS = Path(__file__).resolve().parents[2] / "shared" / "programs"


#: Fixtures of the tests that run LinuxCNC or its interpreter: their tests are marked ``live``.
LIVE_FIXTURES = ("linuxcnc_live", "linuxcnc_interpreter")


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Mark every test that runs LinuxCNC ``live`` (``pytest -m "not live"`` leaves them out;
    ``make test`` runs them all)."""
    for item in items:
        if set(getattr(item, "fixturenames", ())) & set(LIVE_FIXTURES):
            item.add_marker(pytest.mark.live)


@pytest.fixture
def shared_programs() -> Path:
    if not SHARED_PROGRAMS.is_dir():
        pytest.skip("../shared/programs is not beside this clone")
    return SHARED_PROGRAMS


@pytest.fixture
def linuxcnc_live() -> None:
    """Skip a live LinuxCNC test where LinuxCNC cannot run, or fail it where
    ``NCTWIN_REQUIRE_LINUXCNC=1`` (``make test``: the real kernel is proven, not assumed)."""
    from nctwin.kernel.linuxcnc import available

    why = available()
    if why and os.environ.get("NCTWIN_REQUIRE_LINUXCNC") == "1":
        pytest.fail(f"NCTWIN_REQUIRE_LINUXCNC=1 but LinuxCNC cannot run: {why}")
    if why:
        pytest.skip(f"LinuxCNC: {why}")


@pytest.fixture(scope="session")
def linuxcnc_interpreter() -> None:
    """Skip a test of LinuxCNC's interpreter (the ``linuxcnc`` reader) where it is missing, or
    fail it where ``NCTWIN_REQUIRE_LINUXCNC=1`` (``make test``)."""
    from nctwin.gcode import interpreter_available

    if interpreter_available():
        return
    if os.environ.get("NCTWIN_REQUIRE_LINUXCNC") == "1":
        pytest.fail("NCTWIN_REQUIRE_LINUXCNC=1 but LinuxCNC's interpreter is missing")
    pytest.skip("LinuxCNC's interpreter is missing (make linuxcnc)")
