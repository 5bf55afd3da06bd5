"""How a speaker takes back what they just said ("1 meter, no, 2 meters").

One list for the places that read it: the training data writes
self-corrections with these templates, the meaning checks take back a
number or an object said right before one of their markers, and the
normalizer gives a bare number after a marker the unit of the amount it
corrects.
"""

from __future__ import annotations

import re

CORRECTIONS = (", no, {b}", ", sorry, {b}", ", i mean {b}", ", no wait, {b}", ", make that {b}",
               ", actually {b}", ", oops, {b}", ", no sorry, {b}", " - no, {b}", ", or rather {b}")
# What people also say to take something back, which the training data does not write: the runtime
# reads them as it reads the templates' words.
SPOKEN = ("scratch that", "i meant", "correction", "make it")
# The words of each template, longest first so that "no wait" is read before "no".
MARKERS = tuple(sorted({re.sub(r"[^a-z ]", "", t.replace("{b}", "")).strip() for t in CORRECTIONS} | set(SPOKEN),
                       key=len, reverse=True))
