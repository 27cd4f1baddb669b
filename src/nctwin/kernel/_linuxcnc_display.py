#!/usr/bin/python3
"""LinuxCNC "display" that runs one program headless and records it (nctwin.kernel.linuxcnc).

LinuxCNC starts this script as ``DISPLAY`` program with ``-ini INIFILE``; it runs under the system
Python (``/usr/bin/python3``), where LinuxCNC's ``linuxcnc`` module lives, never inside nctwin.
In the folder of the INI file it reads ``program.ngc``, records the sampler's FIFO with
``halsampler -t`` into ``samples.txt`` while the program runs, and writes ``result.json``:
``{"ok": true}``, ``{"ok": false, "message": "<LinuxCNC's error>"}`` or, if LinuxCNC did not carry
out a command in time, ``{"ok": false, "stuck": "<what>"}``. When it exits, LinuxCNC shuts down.
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
#: Task states that wait for the (held) motion.
WAITING_FOR_MOTION = (
    linuxcnc.EXEC_WAITING_FOR_MOTION,
    linuxcnc.EXEC_WAITING_FOR_MOTION_QUEUE,
    linuxcnc.EXEC_WAITING_FOR_MOTION_AND_IO,
)
#: Error-channel kinds that abort the run (operator text and display messages do not).
ERROR_KINDS = (linuxcnc.NML_ERROR, linuxcnc.OPERATOR_ERROR)


class Rejected(Exception):
    """LinuxCNC reported an error."""


class Stuck(Exception):
    """LinuxCNC did not carry out a command in time."""


def check_errors(errors):
    """Raise Rejected with the first error message waiting on the error channel."""
    while True:
        msg = errors.poll()
        if not msg:
            return
        kind, text = msg
        if kind in ERROR_KINDS:
            raise Rejected(text)


def command(cmd, errors, call, *args):
    """Send one command and wait until task has completed it."""
    getattr(cmd, call)(*args)
    if cmd.wait_complete(COMMAND_TIMEOUT_S) == -1:
        raise Stuck(f"LinuxCNC did not complete {call}{args} within {COMMAND_TIMEOUT_S} s")
    check_errors(errors)


def release(cmd, stat, errors):
    """Set both overrides back to 1 while the program runs (task completes no command then)."""
    cmd.feedrate(1.0)
    cmd.rapidrate(1.0)
    deadline = time.monotonic() + COMMAND_TIMEOUT_S
    while True:
        check_errors(errors)
        stat.poll()
        if stat.feedrate == 1.0 and stat.rapidrate == 1.0:
            return
        if time.monotonic() > deadline:
            raise Stuck(f"LinuxCNC did not set the overrides to 1 within {COMMAND_TIMEOUT_S} s")
        time.sleep(POLL_S)


def run(folder):
    stat, cmd, errors = linuxcnc.stat(), linuxcnc.command(), linuxcnc.error_channel()
    command(cmd, errors, "state", linuxcnc.STATE_ESTOP_RESET)
    command(cmd, errors, "state", linuxcnc.STATE_ON)
    command(cmd, errors, "mode", linuxcnc.MODE_AUTO)
    command(cmd, errors, "program_open", os.path.join(folder, "program.ngc"))
    with open(os.path.join(folder, "samples.txt"), "w") as out:
        sampler = subprocess.Popen(["halsampler", "-t"], stdout=out)
        try:
            # Hold the motion (overrides at 0) until the interpreter has queued the whole
            # program or filled the queue: otherwise the planner starts with whatever the
            # interpreter has read so far, and its look-ahead depends on wall-clock time.
            command(cmd, errors, "feedrate", 0.0)
            command(cmd, errors, "rapidrate", 0.0)
            # Task completes AUTO_RUN only when the program has run. It passes the interpreted
            # moves to the planner's queue a few per task cycle; while the motion is held and
            # moves are queued, it ends up waiting for the motion (at the program's end or a
            # queue buster), or the queue is full. Waits for I/O are passing. Only a program
            # without motion goes back to idle (if that happens between two polls, the caller's
            # timeout ends the run).
            cmd.auto(linuxcnc.AUTO_RUN, 0)
            started = False
            while True:
                check_errors(errors)
                stat.poll()
                if stat.queue_full or (stat.queue > 0 and stat.exec_state in WAITING_FOR_MOTION):
                    break
                if stat.task_paused:  # an M0/M1 before the first move: resumed below
                    break
                if started and stat.interp_state == linuxcnc.INTERP_IDLE:
                    break
                started = started or stat.interp_state != linuxcnc.INTERP_IDLE
                time.sleep(POLL_S)
            release(cmd, stat, errors)
            while True:
                check_errors(errors)
                stat.poll()
                if stat.interp_state == linuxcnc.INTERP_IDLE and stat.queue == 0 and stat.inpos:
                    break
                if stat.task_paused:  # M0, M1: the operator presses cycle start at once
                    cmd.auto(linuxcnc.AUTO_RESUME)
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
    except Stuck as exc:
        result = {"ok": False, "stuck": str(exc)}
    with open(os.path.join(folder, "result.json"), "w") as fh:
        json.dump(result, fh)


if __name__ == "__main__":
    main()
