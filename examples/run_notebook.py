"""Executes a notebook with nbclient in the current Python environment, from the notebook's
own folder, and fails if any cell raises: `.ci/run` runs the examples' notebook this way.

    python examples/run_notebook.py examples/platen-quickstart.ipynb [--out executed.ipynb]
"""

import argparse
import sys
from pathlib import Path

import nbclient
import nbformat


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("notebook", type=Path)
    parser.add_argument("--out", type=Path, help="write the executed notebook here")
    parser.add_argument("--timeout-s", type=int, default=600, help="per cell")
    args = parser.parse_args()
    nb = nbformat.read(args.notebook, as_version=4)
    client = nbclient.NotebookClient(
        nb,
        timeout=args.timeout_s,
        kernel_name="python3",
        resources={"metadata": {"path": str(args.notebook.resolve().parent)}},
    )
    client.execute()
    for cell in nb.cells:
        for output in cell.get("outputs", []):
            if output.get("output_type") == "stream":
                sys.stdout.write(output.get("text", ""))
    if args.out:
        nbformat.write(nb, args.out)
    print(f"{args.notebook}: {len(nb.cells)} cells executed without error")
    return 0


if __name__ == "__main__":
    sys.exit(main())
