"""The runtime never imports training code, and the adapter's runtime part imports no runtime above it.

Layers, each importing only the ones before it:
1. the adapter's runtime interface, `agent.adapter.prompt` (the prompt format an adapter was trained on)
   and `agent.adapter.card` (what an adapter was made for): rsl/ and agent.normalize only;
2. the runtime (daemon, translation, backends, speech, CLI): layer 1, never training code;
3. training (`agent.adapter.data`, `train`, `export`, `hygiene`, `evaluate`): anything.
`nrtrans train-adapter` is the one runtime module that reaches training code, inside its handler.
"""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path

from tests.layers.modules import ROOT, TRAINING_ONLY, module_name, runtime_modules

TRAINING_COMMAND = "agent.commands.train_adapter"
HEAVY = ("torch", "transformers", "peft", "datasets", "accelerate", "gguf")


def imports(path: Path) -> list[tuple[int, str, bool]]:
    """(line, module, at module level) for every import in `path`, lazy ones included."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    top = {id(node) for node in tree.body}
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name, id(node) in top) for alias in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found += [(node.lineno, node.module, id(node) in top)]
            found += [(node.lineno, f"{node.module}.{alias.name}", id(node) in top) for alias in node.names]
    return found


def training_imports(path: Path, name: str) -> list[str]:
    found = []
    for line, imported, at_top in imports(path):
        if imported in TRAINING_ONLY or imported.split(".")[0] in HEAVY:
            if name == TRAINING_COMMAND and not at_top:
                continue
            found.append(f"{name}:{line}: imports {imported}")
    return found


def _within(imported: str, modules: frozenset[str]) -> bool:
    return any(imported == m or imported.startswith(f"{m}.") for m in modules)


def test_no_runtime_module_imports_training_code() -> None:
    found = [entry for path in runtime_modules() for entry in training_imports(path, module_name(path))]
    assert not found, "runtime code imports training code:\n  " + "\n  ".join(found)


def test_the_adapter_interface_imports_nothing_above_it() -> None:
    below = frozenset({"agent.normalize", "agent.adapter.card", "agent.adapter.prompt"})
    found = []
    for path in (ROOT / "agent" / "adapter" / name for name in ("__init__.py", "card.py", "prompt.py")):
        for line, imported, _ in imports(path):
            if imported.startswith("agent") and imported != "agent.adapter" and not _within(imported, below):
                found.append(f"{path.relative_to(ROOT)}:{line}: imports {imported}")
    assert not found, "the adapter's runtime interface depends on the runtime above it:\n  " + "\n  ".join(found)


def test_the_search_sees_lazy_imports(tmp_path: Path) -> None:
    path = tmp_path / "example.py"
    path.write_text("import os\n\ndef handler():\n    from agent.adapter import data\n    import torch\n",
                    encoding="utf-8")
    assert training_imports(path, "agent.commands.example") == [
        "agent.commands.example:4: imports agent.adapter.data", "agent.commands.example:5: imports torch"]
    assert training_imports(path, TRAINING_COMMAND) == []


def test_starting_the_daemon_translator_and_cli_loads_no_training_code() -> None:
    program = ("import json, sys\n"
               "import agent.daemon.service, agent.translate.translator, agent.cli\n"
               "agent.cli.build_parser()\n"
               "print(json.dumps(sorted(sys.modules)))\n")
    done = subprocess.run([sys.executable, "-c", program], cwd=ROOT, capture_output=True, text=True,
                          check=False, timeout=120)
    assert done.returncode == 0, done.stderr
    loaded = set(json.loads(done.stdout))
    heavy = sorted(m for m in loaded if m.split(".")[0] in HEAVY)
    training = sorted(loaded & TRAINING_ONLY)
    assert not heavy and not training, f"startup loaded {heavy + training}"
    assert "agent.daemon.service" in loaded and "agent.commands.train_adapter" in loaded
