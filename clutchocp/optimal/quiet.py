"""Native solver output kept from the terminal: IPOPT, CasADi and SUNDIALS print from C/C++ straight to
the process's file descriptors 1 and 2, past Python's ``sys.stdout``. ``clutchocp optimize`` speaks for
them (a solver's status is said in words, :func:`clutchocp.optimal.problem.solver_verdict`), so their
own lines are caught here and handed to the caller instead.
"""

import os
import sys
import tempfile
from contextlib import contextmanager


@contextmanager
def native_output_caught():
    """Within the block, whatever native code writes to file descriptors 1 and 2 goes to a temporary
    file; yields a list that holds that text (stripped, possibly empty) after the block.

    Python's own streams are flushed first, so nothing printed before the block is lost or reordered.
    Where the descriptors cannot be redirected (no real descriptors, e.g. under some notebooks) the
    block runs unchanged and the list stays empty.
    """
    caught = []
    try:
        saved = [os.dup(1), os.dup(2)]
    except OSError:
        yield caught
        return
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (AttributeError, ValueError):
            pass
    with tempfile.TemporaryFile(mode="w+b") as sink:
        try:
            os.dup2(sink.fileno(), 1)
            os.dup2(sink.fileno(), 2)
            yield caught
        finally:
            for stream in (sys.stdout, sys.stderr):
                try:
                    stream.flush()
                except (AttributeError, ValueError):
                    pass
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)
            sink.seek(0)
            text = sink.read().decode("utf-8", "replace").strip()
            if text:
                caught.append(text)
