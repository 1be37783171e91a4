#!/usr/bin/env python3
"""The batch workflow (batch/Snakefile through scripts/batch.sh; issue 41), run for real.

  batch_test.py local DAYLIT SOURCE_DIR WORK  Snakemake on this machine's cores: two bundled
      recordings and a broken one; every good recording's outputs complete, the broken one
      listed as failed with daylit's one-line error, the tables and plot agreeing with each
      recording's own figures; a second run does nothing, and a removed step's output is redone
      alone.
  batch_test.py slurm DAYLIT SOURCE_DIR WORK  the same workflow through Snakemake's Slurm
      executor against a real single-node Slurm (Debian's slurmctld, slurmd and munged, started
      in WORK with their own ports and stopped at the end); then a cluster that is not
      reachable: one line, exit 1.

WORK is emptied first. Frames are few (--frames): the steps are tested whole elsewhere.
"""
import csv
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time

MODE, DAYLIT, SOURCE, WORK = sys.argv[1:5]
FRAMES = 12
failures = []


def check(condition, what):
    print(("ok    " if condition else "FAIL  ") + what, flush=True)
    if not condition:
        failures.append(what)


def run(command, env=None, timeout=900):
    print("$ " + " ".join(command), flush=True)
    result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env,
                            timeout=timeout)
    return result


def make_recordings(folder, good):
    """The bundled recordings as links, and `broken`: courtyard-a's files with a latitude of 123."""
    os.makedirs(folder)
    for name in good:
        os.symlink(os.path.join(SOURCE, "recordings", name), os.path.join(folder, name))
    broken = os.path.join(folder, "broken")
    os.makedirs(broken)
    a = os.path.join(SOURCE, "recordings", "courtyard-a")
    for entry in os.listdir(a):
        if entry != "scene.json":
            os.symlink(os.path.join(a, entry), os.path.join(broken, entry))
    with open(os.path.join(a, "scene.json"), encoding="utf-8") as f:
        scene = json.load(f)
    scene["location"]["latitude_deg"] = 123
    with open(os.path.join(broken, "scene.json"), "w", encoding="utf-8") as f:
        json.dump(scene, f, indent=1)


def seed_bakes(cache, good):
    """The test fixture's bakes (ctest's courtyard_bakes), copied: the bake step finds them current."""
    for name in good:
        source = os.path.join(os.path.dirname(os.path.dirname(DAYLIT)), "test-cache", name)
        if os.path.isfile(os.path.join(source, "bake.json")):
            shutil.copytree(source, os.path.join(cache, name))


def read_csv(path):
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def check_outputs(out, good):
    results = {r["recording"]: r for r in read_csv(os.path.join(out, "results.csv"))}
    check(sorted(results) == sorted(good + ["broken"]), f"results.csv lists every recording: {sorted(results)}")
    broken = results.get("broken", {})
    check(broken.get("status") == "failed" and broken.get("failed_step") == "info",
          f"broken is failed at info: {broken.get('status')} {broken.get('failed_step')}")
    check("latitude" in broken.get("reason", "") and "scene.json" in broken.get("reason", ""),
          f"its reason is daylit's line naming the file and field: {broken.get('reason')!r}")
    for step in ("bake", "estimate", "replay"):
        with open(os.path.join(out, "broken", step + ".status"), encoding="utf-8") as f:
            check(f.read().startswith("skipped"), f"broken's {step} was skipped")
    bursts = read_csv(os.path.join(out, "bursts.csv"))
    for name in good:
        r = results.get(name, {})
        check(r.get("status") == "ok", f"{name} ok ({r.get('status')}: {r.get('reason')})")
        folder = os.path.join(out, name)
        for f in ("info.txt", "estimate/estimates.csv", "estimate/bursts.csv", "estimate/report.txt",
                  "estimate/figures.json", "replay/replay.mp4", "replay/report.txt", "replay/figures.json"):
            path = os.path.join(folder, f)
            check(os.path.isfile(path) and os.path.getsize(path) > 0, f"{name}/{f} written")
        with open(os.path.join(folder, "estimate", "figures.json"), encoding="utf-8") as f:
            figures = json.load(f)
        with open(os.path.join(folder, "replay", "figures.json"), encoding="utf-8") as f:
            replay = json.load(f)
        check(r.get("frames") == str(FRAMES) and replay.get("frames") == FRAMES,
              f"{name}: {FRAMES} frames estimated and replayed ({r.get('frames')}, {replay.get('frames')})")
        for column, key in (("sun_half_width", "lighting/interval/sun_half_width"),
                            ("sky_half_width", "lighting/interval/sky_half_width"),
                            ("p90_worst_channel_error", "lighting/p90_worst_channel_error")):
            value = figures.get(key)
            check(value is not None and abs(float(r.get(column) or "nan") - value) <= 1e-3 * abs(value),
                  f"{name}: results.csv {column} {r.get(column)} is its figures.json's {value}")
        own = read_csv(os.path.join(folder, "estimate", "bursts.csv"))
        mine = [b for b in bursts if b["recording"] == name]
        check(len(mine) == len(own) >= 1 and all(
            m["sun_error_r"] == o["sun_error_r"] and m["sky_b_hi"] == o["sky_b_hi"]
            for m, o in zip(mine, own)), f"{name}: bursts.csv holds its {len(own)} burst(s) as they are")
        # An ideal recording's first frames: the interval is stated and holds, the error is a few %.
        worst = float(r.get("worst_burst_error") or "nan")
        check(worst <= 0.10, f"{name}: worst burst error {worst:.3f} within 10% over {FRAMES} frames")
    with open(os.path.join(out, "summary.png"), "rb") as f:
        check(f.read(8) == b"\x89PNG\r\n\x1a\n", "summary.png is a PNG")


def dry_run_jobs(command, env=None):
    """{rule: count} of what a dry run of the same command would run."""
    result = run(command + ["--", "--dry-run", "--quiet"], env=env)
    jobs = {}
    for line in result.stdout.splitlines():
        parts = line.split()
        if len(parts) >= 2 and parts[1].isdigit() and parts[0] in ("info", "bake", "estimate", "replay", "table"):
            jobs[parts[0]] = int(parts[1])
    return result, jobs


def batch_command(recordings, out, extra):
    return ["bash", os.path.join(SOURCE, "scripts", "batch.sh"), recordings, out, "--daylit", DAYLIT,
            "--frames", str(FRAMES), "--cache", os.path.join(WORK, "bake")] + extra


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Slurm:
    """A single-node Slurm cluster in its own folder: munged, slurmctld and slurmd as root."""

    def __init__(self, folder):
        self.folder = folder
        self.env = dict(os.environ, SLURM_CONF=os.path.join(folder, "slurm.conf"))
        for d in ("state", "spool", "munge"):
            os.makedirs(os.path.join(folder, d))
        os.chmod(os.path.join(folder, "munge"), 0o700)
        self.socket = os.path.join(folder, "munge", "socket")
        key = os.path.join(folder, "munge", "munge.key")
        subprocess.run(["mungekey", "--create", "--keyfile", key], check=True)
        host = socket.gethostname().split(".")[0]
        cpus = os.cpu_count() or 1
        config = f"""ClusterName=daylittest
SlurmctldHost={host}(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket={self.socket}
CredType=cred/munge
SlurmctldPort={free_port()}
SlurmdPort={free_port()}
StateSaveLocation={folder}/state
SlurmdSpoolDir={folder}/spool
SlurmctldPidFile={folder}/slurmctld.pid
SlurmdPidFile={folder}/slurmd.pid
SlurmctldLogFile={folder}/slurmctld.log
SlurmdLogFile={folder}/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SwitchType=switch/none
MpiDefault=none
ReturnToService=2
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
MinJobAge=3600
NodeName={host} NodeAddr=127.0.0.1 CPUs={cpus} RealMemory=16000 State=UNKNOWN
PartitionName=test Nodes={host} Default=YES MaxTime=INFINITE State=UP
"""
        with open(self.env["SLURM_CONF"], "w", encoding="utf-8") as f:
            f.write(config)

    def start(self):
        m = os.path.join(self.folder, "munge")
        subprocess.run(["munged", "--force", f"--socket={self.socket}", f"--key-file={m}/munge.key",
                        f"--log-file={m}/munged.log", f"--pid-file={m}/munged.pid", f"--seed-file={m}/seed"],
                       check=True)
        subprocess.run(["slurmctld"], env=self.env, check=True)
        subprocess.run(["slurmd"], env=self.env, check=True)
        for _ in range(60):
            r = subprocess.run(["sinfo", "--noheader", "--format=%T"], env=self.env, capture_output=True, text=True)
            if r.returncode == 0 and r.stdout.strip() == "idle":
                return True
            time.sleep(0.5)
        return False

    def stop(self):
        subprocess.run(["scontrol", "shutdown"], env=self.env, capture_output=True)
        for pid_file in ("slurmd.pid", "slurmctld.pid", "munge/munged.pid"):
            try:
                with open(os.path.join(self.folder, pid_file), encoding="utf-8") as f:
                    pid = int(f.read().strip())
            except (FileNotFoundError, ValueError):
                continue
            for _ in range(50):
                try:
                    os.kill(pid, 0 if _ else signal.SIGTERM)
                except ProcessLookupError:
                    break
                time.sleep(0.1)


def main():
    shutil.rmtree(WORK, ignore_errors=True)
    os.makedirs(WORK)
    recordings = os.path.join(WORK, "recordings")
    out = os.path.join(WORK, "out")
    good = ["courtyard-a", "courtyard-b"] if MODE == "local" else ["courtyard-a"]
    make_recordings(recordings, good)
    seed_bakes(os.path.join(WORK, "bake"), good)

    if MODE == "local":
        command = batch_command(recordings, out, ["--cores", "2"])
        result = run(command)
        print(result.stdout[-4000:])
        check(result.returncode == 0, f"the batch exits 0 past a broken recording (exit {result.returncode})")
        check_outputs(out, good)
        result, jobs = dry_run_jobs(command)
        check(result.returncode == 0 and not jobs, f"run again, nothing to do: {jobs}")
        os.remove(os.path.join(out, "courtyard-b", "replay.status"))
        result, jobs = dry_run_jobs(command)
        check(jobs == {"replay": 1, "table": 1}, f"a step whose output is gone is redone alone: {jobs}")
        # The broken recording fixed: its scene.json is newer than its status, so it alone runs again.
        path = os.path.join(recordings, "broken", "scene.json")
        with open(path, encoding="utf-8") as f:
            scene = json.load(f)
        scene["location"]["latitude_deg"] = 57.05
        with open(path, "w", encoding="utf-8") as f:
            json.dump(scene, f, indent=1)
        result, jobs = dry_run_jobs(command)
        check(jobs == {"info": 1, "bake": 1, "estimate": 1, "replay": 2, "table": 1},
              f"a fixed recording runs again, with the removed step: {jobs}")
    else:
        if os.geteuid() != 0:
            print("skipped: a Slurm cluster of one's own needs root (slurmd runs each job as its user)", flush=True)
            return 77
        slurm = Slurm(os.path.join(WORK, "slurm"))
        try:
            check(slurm.start(), "the single-node Slurm cluster is up (sinfo: idle)")
            # Snakemake polls Slurm every 33 s by default (and above 1 a second), polite on a real cluster; here once a second.
            command = batch_command(recordings, out, ["--slurm", "--jobs", "4", "--", "--max-status-checks-per-second", "1"])
            result = run(command, env=slurm.env)
            print(result.stdout[-4000:])
            check(result.returncode == 0, f"the batch on Slurm exits 0 past a broken recording (exit {result.returncode})")
            check_outputs(out, good)
            logs = os.path.join(out, ".snakemake", "slurm_logs")
            ran = sorted(d for d in os.listdir(logs)) if os.path.isdir(logs) else []
            check(ran == ["rule_bake", "rule_estimate", "rule_info", "rule_replay", "rule_table"],
                  f"every rule ran as a Slurm job: {ran}")
        finally:
            slurm.stop()
        # The cluster is gone now: one line, exit 1, before any job.
        result = run(batch_command(recordings, os.path.join(WORK, "out2"), ["--slurm"]), env=slurm.env, timeout=120)
        lines = [l for l in result.stdout.splitlines() if l.strip()]
        check(result.returncode == 1 and len(lines) == 1 and "not reachable" in lines[0],
              f"no cluster: one line, exit 1 (exit {result.returncode}: {lines[:3]})")
    if failures:
        print(f"{len(failures)} check(s) failed", flush=True)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
