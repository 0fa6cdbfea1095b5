"""The ``eyestereo`` command line (entry point :func:`eyestereo.tools.cli.main.main`): one module per
group of subcommands."""
