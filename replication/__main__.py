"""``python -m replication experiment=<name> [overrides]``: run an experiment and write its report."""

from replication.cli import main

if __name__ == "__main__":
    main()
