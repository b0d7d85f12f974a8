"""``python -m vrlib``: the command line (:mod:`vrlib.cli`)."""

from vrlib.cli import main

if __name__ == "__main__":
    raise SystemExit(main())
