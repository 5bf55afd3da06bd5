"""The default profile with every skill keyword renamed: proof that no code below the profile
knows a keyword. Built from the shipped profile at test time, so it follows every change to it."""

from __future__ import annotations

import re
from pathlib import Path

from rsl.profile import default_profile_path

RENAMED = {
    "forward": "fwdmove", "backward": "revmove", "turnleft": "spinccw", "turnright": "spincw",
    "lookup": "headup", "lookdown": "headdown", "lookleft": "headccw", "lookright": "headcw",
    "perceive": "sense", "approach": "closein", "grasp": "clutch", "goto": "travel",
}
FETCH_AND_RETURN = "sense;\nclosein table;\nclutch cup;\ntravel 0, 0;\n"
_WORD = re.compile(r"\b(" + "|".join(RENAMED) + r")\b")
# Only the lines that name skills: descriptions and aliases keep their English words.
_SKILL_LINE = re.compile(r'^(keyword|opposite|out_of_reach|example|program) = ".*"$', re.M)


def renamed_profile_text() -> str:
    text = default_profile_path().read_text(encoding="utf-8")
    text = text.replace('name = "default"', 'name = "renamed"')
    return _SKILL_LINE.sub(lambda m: _WORD.sub(lambda w: RENAMED[w.group(1)], m.group(0)), text)


def write_renamed_profile(folder: Path) -> Path:
    path = folder / "renamed.toml"
    path.write_text(renamed_profile_text(), encoding="utf-8")
    return path
