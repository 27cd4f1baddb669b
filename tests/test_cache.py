"""nctwin.cache: cached data are named by what they were made from and the CPU kernels numpy
computes with."""

from __future__ import annotations

import os
import subprocess
import sys

from nctwin.cache import cache_path, content_key, numpy_cpu_features

_NAME_AND_V4 = (
    "from nctwin.cache import cache_path, numpy_cpu_features; "
    "print(cache_path('k', 'n', 'abc', '.npz').name, 'X86_V4' in numpy_cpu_features())"
)


def _run(env: dict) -> tuple[str, bool]:
    out = subprocess.run([sys.executable, "-c", _NAME_AND_V4], env=env, capture_output=True,
                         text=True, check=True).stdout.split()  # fmt: skip
    return out[0], out[1] == "True"


def test_the_name_holds_the_key_and_the_cpu_kernels():
    path = cache_path("kind", "name", "abc", ".npz")
    assert path.parent.name == "kind"
    assert path.name == f"name-{content_key('abc', numpy_cpu_features())[:16]}.npz"
    assert cache_path("kind", "name", "abd", ".npz") != path


def test_data_computed_with_other_cpu_kernels_get_another_name():
    # make pins numpy to its AVX2 kernels; a run outside make on an AVX-512 CPU does not
    pinned = dict(os.environ, NPY_DISABLE_CPU_FEATURES="X86_V4 AVX512_ICL AVX512_SPR")
    free = {k: v for k, v in os.environ.items() if k != "NPY_DISABLE_CPU_FEATURES"}
    (name_pinned, _), (name_free, has_v4) = _run(pinned), _run(free)
    assert (name_pinned != name_free) == has_v4
