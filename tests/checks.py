"""The little harness the Python tests outside Blender share: the command
line (BLENDTOOL SOURCE_DIR WORK_DIR), check() that records a failure and
goes on, and finish() that prints the summary and sets the exit status."""
import os
import sys

failures = []


def args():
    """(BLENDTOOL, SOURCE_DIR, WORK_DIR) from the command line; WORK_DIR is made."""
    blendtool, src, work = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    return blendtool, src, work


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL: " + what)


def finish(name, ok_message):
    if failures:
        print("%s: %d failures" % (name, len(failures)))
        sys.exit(1)
    print("%s: %s" % (name, ok_message))
