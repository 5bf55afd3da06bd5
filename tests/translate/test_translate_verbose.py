"""`nrtrans translate -v` tells a person what the loop does: clauses, passes, problems, timings."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path


def test_verbose_shows_clauses_passes_and_timings(model_path: Path) -> None:
    done = subprocess.run([sys.executable, "-m", "agent.cli", "translate", "-v", "--model", str(model_path),
                           "move forward one meter then turn left"], capture_output=True, text=True, timeout=300,
                          env={**os.environ}, check=False)
    assert done.returncode == 0, done.stderr
    lines = [line for line in done.stderr.splitlines() if line.startswith("translate: ")]
    text = "\n".join(lines)
    assert re.search(r"^translate: model \S+ loaded in \d+\.\d s$", text, re.MULTILINE), done.stderr
    assert re.search(r"^translate: task 'move forward one meter then turn left', normalized .*: 2 clause\(s\): "
                     r"'.*' \| '.*'$", text, re.MULTILINE), done.stderr
    assert re.search(r"^translate: pass 1, clause '.*' -> 'forward 1;' \(prompt \d+ ms, generation \d+ ms\)$",
                     text, re.MULTILINE), done.stderr
    assert re.search(r"^translate: pass 1: verified$", text, re.MULTILINE), done.stderr
    assert re.search(r"^translate: verified after 1 pass\(es\) in \d+ ms: prompt \d+ ms, generation \d+ ms, "
                     r"compile \d+\.\d ms$", text, re.MULTILINE), done.stderr
    assert "-- attempt" not in done.stderr
    assert done.stdout == "forward 1;\nturnleft 1.5708;\n"
