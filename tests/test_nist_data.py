"""NIST's SMS Test Bed data shipped in ``data/nist/``: every file is the one its README lists
(size and SHA-256), the folders hold nothing else, and the README gives the source, NIST's
notice and the credit."""

from __future__ import annotations

import hashlib
import re

import pytest

from nctwin.paths import nist_dir

NIST = nist_dir()
README = (NIST / "README.md").read_text()
#: ``| `path` | bytes | `sha256` |`` rows of the README's file table.
ROW = re.compile(r"^\| `([^`]+)` \| (\d+) \| `([0-9a-f]{64})` \|$", re.MULTILINE)
LISTED = {path: (int(size), sha) for path, size, sha in ROW.findall(README)}


def test_the_readme_lists_the_programs_the_logs_and_the_device_file():
    assert sum(p.startswith("nc/") and p.endswith(".NC") for p in LISTED) == 23
    assert sum(p.startswith("logs/") and p.endswith(".txt.gz") for p in LISTED) == 80
    assert "Devices.xml" in LISTED
    assert len(LISTED) == 23 + 80 + 1


def test_the_folders_hold_exactly_the_listed_files():
    shipped = {p.relative_to(NIST).as_posix() for p in NIST.rglob("*") if p.is_file()}
    assert shipped - {"README.md"} == set(LISTED)


@pytest.mark.parametrize("path", sorted(LISTED))
def test_a_shipped_file_is_the_listed_bytes(path):
    data = (NIST / path).read_bytes()
    size, sha = LISTED[path]
    assert len(data) == size, path
    assert hashlib.sha256(data).hexdigest() == sha, path


def test_the_readme_states_the_source_the_notice_and_the_credit():
    text = " ".join(README.split())
    for needle in (
        "usnistgov/smstestbed",
        "968279f14ebe96c03c8877eeb1901cf6b4c8fbab",
        "`tdp/mtc/`",
        '"With the exception of material marked as copyrighted, information presented on these '
        "pages is considered public information and may be distributed or copied. Use of "
        'appropriate byline/photo/image credits is requested."',
        '"We would appreciate acknowledgement if any of the project results are used, however, '
        'the use of the NIST logo is not allowed."',
        "Credit: National Institute of Standards and Technology, Smart Manufacturing Systems "
        "Test Bed (T. Hedberg, M. Helu), https://smstestbed.nist.gov.",
    ):
        assert needle in text, needle
