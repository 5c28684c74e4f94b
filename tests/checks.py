"""The little harness the Python tests outside Blender share: the command
line (BLENDTOOL SOURCE_DIR WORK_DIR), fail() and check() that record a
failure and go on (the list is `failures`), and finish() that prints the
summary and sets the exit status. A test in a folder below tests/ puts
tests/ on sys.path first."""
import os
import sys

failures = []


def args():
    """(BLENDTOOL, SOURCE_DIR, WORK_DIR) from the command line; WORK_DIR is made."""
    blendtool, src, work = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    return blendtool, src, work


def fail(what):
    failures.append(what)
    print("FAIL: " + what)


def check(cond, what):
    """records what as a failure unless cond; returns cond"""
    if not cond:
        fail(what)
    return cond


def finish(name, ok_message):
    if failures:
        print("%s: %d failures" % (name, len(failures)))
        sys.exit(1)
    print("%s: %s" % (name, ok_message))
