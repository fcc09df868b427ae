#!/usr/bin/env python3
"""docs/testing.md: the table of the generators, as --list prints it."""

import os
import sys

from common import ROOT, run, serve


def generators():
    return run([sys.executable, os.path.join(ROOT, "scripts", "docs-figures", "main.py"), "--list"])


if __name__ == "__main__":
    serve({"testing-generators": generators})
