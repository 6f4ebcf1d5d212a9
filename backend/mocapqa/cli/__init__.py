"""The ``mocapqa`` command line (Typer + Rich). Entry point: :func:`mocapqa.cli.main.main`."""
