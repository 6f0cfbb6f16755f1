"""The command line's commands, one module each (see ``studio.cli.COMMANDS``)."""
