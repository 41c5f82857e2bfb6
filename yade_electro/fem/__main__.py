"""Print the mesh-converged FEM reference values of the DEM cases as one JSON line.

    /usr/bin/python3 -m yade_electro.fem            # defaults of docs/fem.md (~1 min)
    /usr/bin/python3 -m yade_electro.fem --quick    # coarser meshes (seconds)
"""
import argparse
import json
import logging
import time

from .references import notched_bar_reference, plate_reference, rod_reference


def main(argv=None):
    """Run the three reference studies and print their summaries."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="coarser meshes")
    ap.add_argument("-v", "--verbose", action="store_true")
    args = ap.parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING)
    k = 2.0 if args.quick else 1.0
    t0 = time.time()
    out = {
        "rod": rod_reference(hs=tuple(k * h for h in (0.2e-3, 0.1e-3, 0.05e-3))),
        "plate": plate_reference(hs=tuple(k * h for h in (2e-3, 1e-3, 0.5e-3))),
        "notched_bar": notched_bar_reference(hs=tuple(k * h for h in (0.2e-3, 0.1e-3, 0.05e-3))),
    }
    summary = {case: {q: c.as_dict() for q, c in res.items()} for case, res in out.items()}
    summary["seconds"] = time.time() - t0
    print(json.dumps(summary))


if __name__ == "__main__":
    main()
