# Shared fixtures of the Python package's tests: the fixture corpus, the command and
# meshstream-gen of the same build (tests/CMakeLists.txt passes their paths in the environment),
# and generated meshes, made once per session.
import json
import os
import subprocess

import pytest

FIXTURES = os.environ.get("MESHSTREAM_FIXTURES_DIR",
                          os.path.join(os.path.dirname(__file__), "..", "..", "fixtures"))
BINARY = os.environ.get("MESHSTREAM_BINARY", "meshstream")
GEN = os.environ.get("MESHSTREAM_GEN_BINARY", "meshstream-gen")


def fixture(*parts):
    return os.path.join(FIXTURES, *parts)


def run_json(*args):
    """The command's --json object (info and compare print JSON with --json alone)."""
    out = subprocess.run([BINARY, *args, "--json"], check=True, capture_output=True, text=True).stdout
    return json.loads(out)


# What changes from run to run in a report: time and memory.
TIMINGS = {"seconds", "triangles_per_second", "peak_rss_bytes"}


def without_timings(report):
    return {k: v for k, v in report.items() if k not in TIMINGS}


@pytest.fixture(scope="session")
def generated(tmp_path_factory):
    """A generated 200 000-triangle binary STL (meshstream-gen's sphere-like surface)."""
    path = tmp_path_factory.mktemp("gen") / "gen.stl"
    subprocess.run([GEN, "-q", "-n", "200000", str(path)], check=True)
    return str(path)


@pytest.fixture(scope="session")
def coloured(tmp_path_factory):
    """A generated 60 000-triangle PLY with vertex colours."""
    path = tmp_path_factory.mktemp("gen") / "coloured.ply"
    subprocess.run([GEN, "-q", "--color", "-n", "60000", str(path)], check=True)
    return str(path)
