"""Entry point for ``python -m ar3cli``."""

from ar3cli.cli import run

if __name__ == "__main__":
    run()
