from roc.cli.main import main
from roc.cli.process_exit import finish

finish(main())
