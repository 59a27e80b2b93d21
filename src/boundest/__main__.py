"""``python -m boundest ...``: the ``boundest`` command (:func:`boundest.cli.console`)."""

if __name__ == "__main__":
    from .cli import console

    console()
