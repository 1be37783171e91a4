#!/usr/bin/env python3
"""One step of the batch workflow (batch/Snakefile) for one recording: runs a daylit command
and writes the step's status file, the job's only declared output.

  step.py --status S [--after PREV] [--log L] [--stdout F] -- daylit COMMAND ...

The status file holds one line: "ok", "failed: <daylit's error line>" or "skipped: <why>".
- PREV not "ok": the command is not run; this step is "skipped" (the recording failed earlier).
- exit 0: "ok"; --stdout's file is written (to a temporary name, then renamed).
- exit 2 (daylit refuses the recording's input: the recording's own problem, which running it
  again does not change): "failed: <the error>", and the step exits 0 so that the batch goes on
  and the tables list it.
- any other exit (1: what the machine lacks, 3: a bug, a signal: killed for time or memory), or
  a SIGTERM to this step (a cluster's time limit: daylit, which gets it too, ends with complete
  files, but not the whole run): no status file, and the step exits non-zero; the job fails in
  Snakemake, which can run it again without redoing the others.
The command's stderr goes to --log and to this step's stderr (Snakemake's or Slurm's log).
"""
import argparse
import os
import signal
import subprocess
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
from files import write_atomically  # noqa: E402


def error_line(stderr_text):
    """daylit's one-line error: its last line that says error, else its last line."""
    lines = [l.strip() for l in stderr_text.splitlines() if l.strip()]
    line = next((l for l in reversed(lines) if "error" in l.lower()), lines[-1] if lines else "no message")
    return line[len("[error] "):] if line.startswith("[error] ") else line


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--status", required=True)
    parser.add_argument("--after")
    parser.add_argument("--log")
    parser.add_argument("--stdout")
    parser.add_argument("command", nargs=argparse.REMAINDER)
    args = parser.parse_args()
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        parser.error("no command after --")

    if args.after:
        with open(args.after, encoding="utf-8") as f:
            previous = f.readline().strip()
        if previous != "ok":
            step = os.path.splitext(os.path.basename(args.after))[0]
            write_atomically(args.status, f"skipped: {step} did not succeed\n".encode())
            return 0

    if args.log:
        os.makedirs(os.path.dirname(os.path.abspath(args.log)), exist_ok=True)
    log = open(args.log, "w", encoding="utf-8") if args.log else None
    try:
        process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    except OSError as e:  # no daylit binary there: the machine's
        print(f"step: cannot run {command[0]}: {e.strerror}", file=sys.stderr)
        return 1
    # A cluster's SIGTERM (its time limit, scancel) reaches every process of the job: daylit ends
    # its frame and writes complete files, but what it did is not the whole step, so no status.
    terminated = []
    signal.signal(signal.SIGTERM, lambda *_: terminated.append(True))
    stdout, stderr = process.communicate()
    text = stderr.decode("utf-8", "replace")
    sys.stderr.write(text)
    if log:
        log.write(text)
        log.close()
    if terminated:
        print(f"step: {command[1] if len(command) > 1 else command[0]} was stopped (SIGTERM) before it finished",
              file=sys.stderr)
        return 128 + signal.SIGTERM
    if process.returncode == 0:
        if args.stdout:
            write_atomically(args.stdout, stdout)
        write_atomically(args.status, b"ok\n")
        return 0
    if process.returncode == 2:
        write_atomically(args.status, f"failed: {error_line(text)}\n".encode())
        return 0
    code = process.returncode
    return code if code > 0 else 128 - code


if __name__ == "__main__":
    sys.exit(main())
