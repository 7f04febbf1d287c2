from granulate.cli import main

raise SystemExit(main())
