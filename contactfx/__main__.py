"""``python3 -m contactfx``: the command line."""

import importlib.util
import sys

if importlib.util.find_spec("contactfx.meshes") is None:
    # This contactfx is the source folder (the current directory) seen by an interpreter
    # it is not installed for: contactfx.meshes (the top-level meshes/) exists only installed.
    sys.exit(
        f"contactfx: error: contactfx is not installed for {sys.executable}: use the venv of "
        "scripts/install.sh (.venv/bin/python -m contactfx, or source .venv/bin/activate)"
    )

from contactfx.cli import main  # noqa: E402

sys.exit(main())
