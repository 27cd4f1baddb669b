#!/usr/bin/python3
"""LinuxCNC "display" that runs one program headless and records it (nctwin.kernel.linuxcnc).

LinuxCNC starts this script as ``DISPLAY`` program with ``-ini INIFILE``; it runs under the system
Python (``/usr/bin/python3``), where LinuxCNC's ``linuxcnc`` module lives, never inside nctwin.
In the folder of the INI file it reads ``program.ngc``, records the sampler's FIFO with
``halsampler -t`` into ``samples.txt`` while the program runs, and writes ``result.json``:
``{"ok": true}`` or ``{"ok": false, "message": "<LinuxCNC's error>"}``. When it exits,
LinuxCNC shuts down.
"""

import json
import os
import signal
import subprocess
import sys
import time

import linuxcnc

#: Poll interval of the status and error channels (s, of the instance's clock).
POLL_S = 0.005
#: Samples recorded at rest after the program ends (s).
TAIL_S = 0.05
#: Longest wait for LinuxCNC to accept a command (s).
COMMAND_TIMEOUT_S = 10.0
#: Wait for a program run (s): in effect none.
RUN_TIMEOUT_S = 1e9
#: Error-channel kinds that abort the run (operator text and display messages do not).
ERROR_KINDS = (linuxcnc.NML_ERROR, linuxcnc.OPERATOR_ERROR)


class Rejected(Exception):
    """LinuxCNC reported an error."""


def check_errors(errors):
    """Raise Rejected with the first error message waiting on the error channel."""
    while True:
        msg = errors.poll()
        if not msg:
            return
        kind, text = msg
        if kind in ERROR_KINDS:
            raise Rejected(text)


def command(cmd, errors, call, *args, timeout_s=COMMAND_TIMEOUT_S):
    """Send one command and wait until task has completed it."""
    getattr(cmd, call)(*args)
    if cmd.wait_complete(timeout_s) == -1:
        raise Rejected(f"LinuxCNC did not complete {call}{args} within {timeout_s} s")
    check_errors(errors)


def run(folder):
    stat, cmd, errors = linuxcnc.stat(), linuxcnc.command(), linuxcnc.error_channel()
    command(cmd, errors, "state", linuxcnc.STATE_ESTOP_RESET)
    command(cmd, errors, "state", linuxcnc.STATE_ON)
    command(cmd, errors, "mode", linuxcnc.MODE_AUTO)
    command(cmd, errors, "program_open", os.path.join(folder, "program.ngc"))
    with open(os.path.join(folder, "samples.txt"), "w") as out:
        sampler = subprocess.Popen(["halsampler", "-t"], stdout=out)
        try:
            # task completes AUTO_RUN when the interpreter is done: no time limit here, the
            # caller kills the instance when its own timeout is reached
            command(cmd, errors, "auto", linuxcnc.AUTO_RUN, 0, timeout_s=RUN_TIMEOUT_S)
            while True:
                check_errors(errors)
                stat.poll()
                if stat.interp_state == linuxcnc.INTERP_IDLE and stat.queue == 0 and stat.inpos:
                    break
                time.sleep(POLL_S)
            time.sleep(TAIL_S)
            check_errors(errors)
        finally:
            sampler.send_signal(signal.SIGINT)
            sampler.wait(COMMAND_TIMEOUT_S)


def main():
    folder = os.path.dirname(os.path.abspath(sys.argv[sys.argv.index("-ini") + 1]))
    try:
        run(folder)
        result = {"ok": True}
    except Rejected as exc:
        result = {"ok": False, "message": str(exc)}
    with open(os.path.join(folder, "result.json"), "w") as fh:
        json.dump(result, fh)


if __name__ == "__main__":
    main()
