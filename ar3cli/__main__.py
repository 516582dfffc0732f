"""Entry point for ``python -m ar3cli``."""

from ar3cli.cli import main

if __name__ == "__main__":
    main()
