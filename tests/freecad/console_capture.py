"""What FreeCAD's console prints while a test's block runs: its warnings and errors go to the
process's stderr (the Report view in the GUI), which a message refusing a change leaves as its
only trace."""

import contextlib
import os
import tempfile


@contextlib.contextmanager
def console_errors():
    """Collects the console's warnings and errors while the block runs: the list yielded holds
    their text after it."""
    text = []
    with tempfile.TemporaryFile(mode="w+") as caught:
        saved = os.dup(2)
        os.dup2(caught.fileno(), 2)
        try:
            yield text
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            caught.seek(0)
            text.append(caught.read())
