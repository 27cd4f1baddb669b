"""Where the package finds its folders, and how it names them to a reader."""

from __future__ import annotations

from pathlib import Path

from nctwin.paths import repo_root, shown


def test_a_path_in_the_checkout_is_shown_from_its_top():
    assert shown(repo_root() / "data" / "cache" / "x") == Path("data/cache/x")


def test_a_path_elsewhere_is_shown_whole(tmp_path):
    """A cache set with NCTWIN_CACHE outside the checkout is no error: it is shown as it is."""
    assert shown(tmp_path / "programs") == tmp_path / "programs"
