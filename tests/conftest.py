"""Shared fixtures."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import settings

settings.register_profile("ci", max_examples=200, deadline=None, derandomize=True)
settings.register_profile("dev", max_examples=100, deadline=None)
settings.load_profile("ci")

#: Public programs written by others, beside the clone; absent in a user's clone.
SHARED_PROGRAMS = Path(__file__).resolve().parents[2] / "shared" / "programs"


@pytest.fixture
def shared_programs() -> Path:
    if not SHARED_PROGRAMS.is_dir():
        pytest.skip("../shared/programs is not beside this clone")
    return SHARED_PROGRAMS
