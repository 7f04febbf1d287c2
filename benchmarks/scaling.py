"""Cost per node-step from 100 to 10,000 particles (case `scaling`); same as
``granulate bench --case scaling``. Options: --quick, --threads N, --json."""

from granulate.bench import _parser, main

if __name__ == "__main__":
    args = _parser().parse_args()
    main(args.case or ["scaling"], args.quick, args.threads, args.json, args.out)
