#!/usr/bin/env python3
"""Write a wedge hopper scene (.inp); same as the console command `bulkflow-make-hopper`.

    .venv/bin/python scripts/make_hopper_scene.py -o inputs/demo/wedge_hopper.inp [options]

Options: `--help`; the generator is scripts/bulkflow/scenes/wedge_hopper.py.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))   # works without the editable install too
from bulkflow.scenes.wedge_hopper import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main())
