"""Files written whole or not at all, with the modes of any Unix tool.

A temporary file in the target's folder (tempfile.mkstemp, mode 0600) is
renamed into place; before that it gets the mode a plain open() would have
given: an existing target's mode, else 0666 less the umask. So a render
node running as another user can read what an artist's Blender baked.
"""
import os
import stat
import tempfile


def _umask():
    try:  # Linux: read it without changing it (no race with other threads)
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    old = os.umask(0o022)
    os.umask(old)
    return old


def target_mode(path):
    """The mode a file written at path should have."""
    try:
        return stat.S_IMODE(os.stat(path).st_mode)
    except OSError:
        return 0o666 & ~_umask()


def temp_beside(path, prefix):
    """(fd, name) of a new temporary file in path's folder."""
    d = os.path.dirname(os.path.abspath(path))
    return tempfile.mkstemp(prefix=prefix, suffix=".tmp", dir=d)


def replace(tmp, path):
    """Give tmp its final mode and rename it to path."""
    try:
        os.chmod(tmp, target_mode(path))
    except OSError:  # a file system without Unix modes: keep what it has
        pass
    os.replace(tmp, path)
