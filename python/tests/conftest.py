"""Shared fixtures: the command-line binary the Python results are compared with, and scratch folders."""

import json
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def cli():
    """Run `hylc ARGS...` (HYLC_BIN, else target/release/hylc of this checkout); returns the completed process."""
    binary = Path(os.environ.get("HYLC_BIN", ROOT / "target" / "release" / "hylc"))
    assert binary.exists(), f"{binary}: build the CLI first (cargo build --release)"

    def run(*args, check=True):
        p = subprocess.run([str(binary), *map(str, args)], capture_output=True, text=True)
        if check:
            assert p.returncode == 0, f"hylc {' '.join(map(str, args))}: {p.stderr}"
        return p

    return run


@pytest.fixture(scope="session")
def cli_json(cli):
    """The JSON lines `hylc ARGS... --json` prints, parsed."""

    def run(*args):
        out = cli(*args).stdout
        return [json.loads(line) for line in out.splitlines() if line.startswith("{")]

    return run


@pytest.fixture(scope="session")
def quick_samples(cli, tmp_path_factory):
    """The quick plan sampled on the generated plain weave by the CLI (a sample file with its sidecar), with the
    samples' sensitivities to the yarn parameters."""
    path = tmp_path_factory.mktemp("samples") / "plain.jsonl"
    cli("sample", "plain", "--plan", "quick", "--out", path, "--sensitivities", check=False)
    assert path.exists()
    return path
