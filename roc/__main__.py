from roc.cli.main import main

raise SystemExit(main())
