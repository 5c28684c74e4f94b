"""What the batch tests share (test_batch, test_batch_hostile, test_slurm):
the command line (BLENDTOOL SOURCE_DIR WORK_DIR, WORK_DIR made empty),
check() that records a failure and goes on, bt() that runs blendtool, the
digest of an output folder, and finish() that sets the exit status."""
import hashlib
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from checks import check, fail, failures  # noqa: E402,F401
BT = None


def setup(clean=True):
    """(BLENDTOOL, SOURCE_DIR, WORK_DIR) as absolute paths; WORK_DIR emptied
    when clean, else only made"""
    global BT
    BT, src, work = (os.path.abspath(a) for a in sys.argv[1:4])
    if clean:
        shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work, exist_ok=True)
    return BT, src, work


def bt(*args, cwd=None, timeout=600):
    return subprocess.run([BT, *args], capture_output=True, text=True, cwd=cwd, timeout=timeout)


def digest(folder):
    """relative name -> sha256 of every file a job leaves (the manifests and
    the task lock included), without the logs folders and the sbatch script"""
    out = {}
    for root, dirs, files in os.walk(folder):
        dirs[:] = [d for d in dirs if d != "logs"]
        for n in files:
            if n.endswith(".sbatch"):
                continue
            p = os.path.join(root, n)
            with open(p, "rb") as f:
                out[os.path.relpath(p, folder)] = hashlib.sha256(f.read()).hexdigest()
    return out


def finish():
    print("%d failures" % len(failures))
    sys.exit(1 if failures else 0)
