"""Shared fixtures: the stored expectations (`data/`, made from the command line by `data/make_expected.py`) and a
sample file made by `hylc.sample`."""

import json
from pathlib import Path

import pytest

import hylc

DATA = Path(__file__).resolve().parent / "data"


@pytest.fixture(scope="session")
def expected():
    """The command line's results stored in `data/expected.json`."""
    return json.loads((DATA / "expected.json").read_text())


@pytest.fixture(scope="session")
def quick_samples(tmp_path_factory):
    """The quick plan sampled on the generated plain weave (a sample file with its sidecar), with the samples'
    sensitivities to the yarn parameters."""
    path = tmp_path_factory.mktemp("samples") / "plain.jsonl"
    summary = hylc.sample("plain", path, "quick", sensitivities=True)
    assert summary["written"] == summary["selected"] == 474
    return path
