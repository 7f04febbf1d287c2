"""Peridynamics kernel benchmarks (lps3d_lattice, lps2d_square); same as
``granulate bench --case lps3d_lattice --case lps2d_square``. Options: --quick, --threads N,
--json. The cases are described in granulate/bench.py."""

from granulate.bench import _parser, main

if __name__ == "__main__":
    args = _parser().parse_args()
    main(
        args.case or ["lps3d_lattice", "lps2d_square"],
        args.quick,
        args.threads,
        args.json,
        args.out,
    )
