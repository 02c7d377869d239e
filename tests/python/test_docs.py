# The examples of docs/python.md, run in order in one namespace from a scratch directory that
# links fixtures/, so the page shows code that works.
import os
import re

import pytest

import meshstream

from conftest import FIXTURES

DOC = os.path.join(os.path.dirname(__file__), "..", "..", "docs", "python.md")


def test_the_examples_of_docs_python_md_run(tmp_path, monkeypatch):
    if not hasattr(meshstream, "tiles"):
        pytest.skip("the examples call meshstream.tiles, which a build without glTF lacks")
    blocks = re.findall(r"```python\n(.*?)```", open(DOC).read(), re.S)
    assert len(blocks) == 5
    os.symlink(os.path.abspath(FIXTURES), tmp_path / "fixtures")
    monkeypatch.chdir(tmp_path)
    namespace = {}
    for block in blocks:
        exec(compile(block, DOC, "exec"), namespace)
    assert sorted(os.listdir(tmp_path)) == sorted(
        ["fixtures", "cube.obj", "cube.glb", "one.stl", "lifted.ply", "cactus_10.ply", "cactus_10_sorted.ply",
         "cactus_tiles"])
