#!/usr/bin/env python3
"""One cohort case: runs `colonflat run INPUT -o OUTDIR` and records the outcome in a status file.

Always exits 0 once the status file is written, so one failing case never stops the cohort
(Snakemake keeps scheduling the others and the summary reports the failure). The status file
(JSON) holds: case, input, status (ok|failed), exit_code, error (colonflat's one-line
`colonflat run: error: <file>: <problem>`, or what went wrong), wall_time_s, outdir, command.
Everything colonflat prints (progress, errors) goes to the case's log file.

The command is `colonflat` on PATH (or --colonflat), or, with --image, the same binary inside a
container: `docker|podman run --rm -v D:D ... IMAGE run ...` (entrypoint colonflat) or
`apptainer|singularity exec --bind D ... IMAGE colonflat run ...`, where every D (input and
output folders) is mounted at its own absolute path so paths stay the same inside.
"""
import argparse
import json
import os
import shlex
import subprocess
import sys
import time


def error_line(text, exit_code):
    lines = [l.strip() for l in text.splitlines() if l.strip()]
    for l in reversed(lines):
        if ": error: " in l or l.startswith("error:"):
            return l
    if lines:
        return lines[-1]
    return f"colonflat exited with code {exit_code} and printed nothing"


def command(a, inp, outdir):
    args = ["run", inp, "-o", outdir, "-q"] + shlex.split(a.extra or "")
    if not a.image:
        return shlex.split(a.colonflat) + args
    mounts = sorted({os.path.dirname(inp), os.path.dirname(outdir)})
    if a.engine in ("docker", "podman"):
        c = [a.engine, "run", "--rm", "-w", os.getcwd()]
        if a.engine == "docker":
            c += ["--user", f"{os.getuid()}:{os.getgid()}"]
        for d in sorted(set(mounts) | {os.getcwd()}):
            c += ["-v", f"{d}:{d}"]
        return c + [a.image] + args
    if a.engine in ("apptainer", "singularity"):
        c = [a.engine, "exec"]
        for d in mounts:
            c += ["--bind", d]
        return c + [a.image, "colonflat"] + args
    raise SystemExit(f"run_case: unknown container engine '{a.engine}' (docker, podman, apptainer, singularity)")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--case", required=True)
    p.add_argument("--input", required=True)
    p.add_argument("--outdir", required=True)
    p.add_argument("--status", required=True)
    p.add_argument("--log", required=True)
    p.add_argument("--colonflat", default="colonflat")
    p.add_argument("--extra", default="", help="extra arguments for `colonflat run` (e.g. --set ...)")
    p.add_argument("--image", default="")
    p.add_argument("--engine", default="docker")
    p.add_argument("--timeout", type=float, default=0, help="seconds; 0 = none")
    a = p.parse_args()
    inp, outdir = os.path.abspath(a.input), os.path.abspath(a.outdir)
    os.makedirs(outdir, exist_ok=True)
    os.makedirs(os.path.dirname(os.path.abspath(a.log)), exist_ok=True)
    cmd = command(a, inp, outdir)
    status = {"case": a.case, "input": inp, "outdir": outdir, "command": shlex.join(cmd)}
    t0 = time.monotonic()
    try:
        r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, errors="replace",
                           timeout=a.timeout or None)
        code, out, err = r.returncode, r.stdout, r.stderr
    except subprocess.TimeoutExpired as e:
        code, out, err = -1, "", f"error: timed out after {a.timeout:g} s"
    except OSError as e:
        code, out, err = -1, "", f"error: cannot start {cmd[0]}: {e.strerror}"
    status["wall_time_s"] = round(time.monotonic() - t0, 3)
    status["exit_code"] = code
    with open(a.log, "w") as f:
        f.write(f"$ {status['command']}\n{out}{err}")
    report = os.path.join(outdir, "run_report.json")
    if code == 0 and os.path.isfile(report):
        status["status"], status["error"] = "ok", ""
    elif code == 0:
        status["status"], status["error"] = "failed", "colonflat exited 0 but wrote no run_report.json"
    else:
        status["status"], status["error"] = "failed", error_line(err or out, code)
    tmp = a.status + ".tmp"
    with open(tmp, "w") as f:
        json.dump(status, f, indent=2)
        f.write("\n")
    os.replace(tmp, a.status)
    print(f"case {a.case}: {status['status']} in {status['wall_time_s']:.1f} s"
          + (f": {status['error']}" if status["error"] else ""), file=sys.stderr)


if __name__ == "__main__":
    main()
