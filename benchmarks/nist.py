"""The real machine as a user meets it: ``nctwin calibrate`` on each Hurco's shipped MTConnect
logs (target: under 2 minutes per machine), then ``nctwin estimate`` of the 22,000-line Box OP1
with the profile it wrote (target: under 2 s), each a new process as a user runs them (start-up,
imports, reading). Time: the shortest of :data:`REPEAT` runs of the estimate, one run of each
calibration; the CPU time (user and system) beside it says what the wall time would be on an
idle machine.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from _common import record
from cli import measure

from nctwin.paths import nist_dir

OP1 = "NIST_MTC_CRADA_BOX_REV-A OP1 (Bottom).NC"


def main() -> None:
    logs = nist_dir() / "logs"
    with tempfile.TemporaryDirectory() as tmp:
        for machine in ("Hurco02", "Hurco04"):
            profile = Path(tmp) / f"{machine.lower()}.toml"
            args = ["calibrate", *map(str, sorted(logs.glob(f"*-{machine}-*.txt.gz"))),
                    "--output", str(profile)]  # fmt: skip
            wall, cpu, _ = measure(args, repeat=1)
            record(f"calibrate_{machine}_s", round(wall, 2), "s", "< 120")
            record(f"calibrate_{machine}_cpu_s", round(cpu, 2), "s", "")
        program = str(nist_dir() / "nc" / OP1)
        profile = str(Path(tmp) / "hurco02.toml")
        wall, cpu, peak = measure(["estimate", program, "--machine", profile])
        record("estimate_op1_hurco02_s", round(wall, 3), "s", "< 2")
        record("estimate_op1_hurco02_cpu_s", round(cpu, 3), "s", "")
        record("estimate_op1_hurco02_peak_gb", round(peak, 3), "GB", "")


if __name__ == "__main__":
    main()
