"""The subcommands of ``python -m validate``, one module each: ``add_parser(subparsers)`` registers it,
``run(args)`` runs it and returns its exit status (errors raised for :func:`validate.cli.main`);
:mod:`validate.commands.shared` holds what several of them share."""
