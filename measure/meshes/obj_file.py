"""Writes a generated OBJ file so that a failed or interrupted run leaves no
partial file and any existing one untouched: the mesh goes to a file beside the
target, renamed over it at the end. Shared by measure/meshes/terrain.py and
measure/speed/grid_obj.py."""
import os
import sys


def write_atomically(path, write, tool):
    """Calls `write(partial_path)`, then renames the partial file to `path`.
    Returns the exit status: 0, 2 when the file cannot be written (one line on
    stderr naming `tool` and the path), 130 when interrupted."""
    partial = f"{path}.partial-{os.getpid()}"

    def remove_partial():
        if os.path.exists(partial):
            os.remove(partial)

    try:
        write(partial)
        os.replace(partial, path)
    except OSError as e:
        remove_partial()
        print(f"{tool}: error: cannot write {path}: {e.strerror}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        remove_partial()
        return 130
    return 0
