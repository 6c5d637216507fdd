# Copyright (c) 2026 CMGeom contributors.
# SPDX-License-Identifier: GPL-3.0-or-later
"""Reads the Markdown table bench_simplify writes (header row '| model (faces) | ...'): yields the
cells of each data row, stripped, in file order. Used by the scripts that summarise its runs."""


def rows(path):
    with open(path) as f:
        for line in f:
            if not line.startswith('| ') or line.startswith('| model'):
                continue
            yield [x.strip() for x in line.strip().strip('|').split('|')]
