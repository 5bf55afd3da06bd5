"""`nrtrans demo` (scripts/demo.sh): the main job ends with the pictures of what the robot did."""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

from PIL import Image

from tests.daemon.conftest import NRTRANS


def test_the_demo_prints_where_its_pictures_are(workdir: Path) -> None:
    env = {k: v for k, v in os.environ.items() if k not in ("NRTRANS_SOCKET", "NRTRANS_CONFIG", "STATE_DIRECTORY")}
    env["HOME"] = str(workdir)  # the demo keeps its audit log and pictures under ~/.local/state/nrtrans/demo
    result = subprocess.run([NRTRANS, "demo", "--realtime-factor", "0"], capture_output=True, text=True,
                            timeout=600, env=env)
    assert result.returncode == 0, result.stdout + result.stderr
    pictures = workdir / ".local" / "state" / "nrtrans" / "demo" / "pictures"
    plot = re.search(r"^trajectory plot: (\S+)$", result.stdout, re.MULTILINE)
    animation = re.search(r"^animation: +(\S+)$", result.stdout, re.MULTILINE)
    assert plot and animation, result.stdout
    assert Path(plot.group(1)).parent.parent == pictures
    with Image.open(plot.group(1)) as image:
        assert image.format == "PNG" and image.width > 600
    with Image.open(animation.group(1)) as gif:
        assert gif.format == "GIF" and gif.n_frames > 1
    assert re.search(r"^camera snapshots: [1-9]\d* in ", result.stdout, re.MULTILINE), result.stdout
