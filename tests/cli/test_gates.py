"""Pass/fail gates (--fail-under, --fail-over) on the command line: every short name reaches a
figure of a real result, a failed gate exits 3 naming the figure and still writes the outputs,
an unknown key stops before any work."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from pcmapq.cli import app
from pcmapq.features.names import STRUCTURE_NAMES
from pcmapq.results import gates
from pcmapq.results.figures import TAU_FIELDS
from pcmapq.results.gates import (
    UNDER,
    Gate,
    check,
)
from pcmapq.settings import DETECTOR_NAMES
from testkit.paths import SAMPLE

MAP, TRUTH = str(SAMPLE / "scan.ply"), str(SAMPLE / "truth.yaml")


def _eval(*args: str):
    return CliRunner().invoke(app, ["eval", MAP, TRUTH, "--quiet", *args], prog_name="pcmapq")


@pytest.fixture(scope="module")
def plain(tmp_path_factory) -> tuple[str, dict]:
    """The sample scored without gates: its JSON text and document."""
    path = tmp_path_factory.mktemp("plain") / "plain.json"
    got = _eval("--json", str(path))
    assert got.exit_code == 0, got.output
    return path.read_text(), json.loads(path.read_text())


@pytest.fixture(scope="module")
def gated(plain, tmp_path_factory):
    """The sample scored again with one gate it passes (harris.quality at its own value) and
    one it fails (accuracy.mean at half its value)."""
    doc = plain[1]
    quality = doc["detectors"]["harris"]["quality"]
    accuracy = doc["distances"]["accuracy_m"]["mean"]
    path = tmp_path_factory.mktemp("gated") / "gated.json"
    got = _eval("--json", str(path), "--fail-under", f"harris.quality={quality}",
                "--fail-over", f"accuracy.mean={accuracy / 2}")
    return got, json.loads(path.read_text()), quality, accuracy


def test_every_short_name_reaches_a_figure_of_a_real_result(plain):
    doc = plain[1]
    assert set(doc) <= set(gates.TOP_LEVEL)
    assert set(gates.TOP_LEVEL) - set(doc) == {"alignment_3d", "distances_3d", "map_3d",
                                               "consistency_3d", "structures_3d"}
    taus = [f["tau_m"] for f in doc["distances"]["f_score"]]
    run = set(doc["detectors"])  # a detector not run has no figures
    at_tau = tuple(TAU_FIELDS)  # named at one of the result's taus
    keys = [k for k in gates.short_names() if "3d" not in k and not k.startswith(at_tau)
            and k.split(".")[0] not in STRUCTURE_NAMES  # two 3D clouds' only
            and (k.split(".")[0] not in DETECTOR_NAMES or k.split(".")[0] in run)]
    keys += [f"{name}@{t:g}" for name in at_tau for t in taus]
    # the free space's figures are null for a map without free space (this one is a cloud)
    free = ("contradiction", "free_on_truth", "seen_through")
    assert all(doc["alignment"][k] is None for k in free)
    keys = [k for k in keys if k.split(".")[-1] not in free]
    outcomes = check([Gate(k, 0.0, UNDER) for k in keys], doc)
    assert all(isinstance(o.value, float | int) for o in outcomes)


def test_a_failed_gate_exits_3_naming_the_figure_and_still_writes_outputs(plain, gated):
    got, doc, quality, accuracy = gated
    assert got.exit_code == gates.EXIT_CODE, got.output
    lines = got.stderr.strip().splitlines()
    assert lines == [f"pcmapq: gate failed: accuracy.mean = {accuracy} m, over the bound "
                     f"{accuracy / 2} m (--fail-over)"]
    assert doc["gates"] == [
        {"key": "harris.quality", "path": "detectors.harris.quality", "option": "--fail-under",
         "bound": quality, "value": quality, "passed": True},
        {"key": "accuracy.mean", "path": "distances.accuracy_m.mean", "option": "--fail-over",
         "bound": accuracy / 2, "value": accuracy, "passed": False}]
    ungated = {k: v for k, v in doc.items() if k not in ("gates", "pcmapq")}
    assert ungated == {k: v for k, v in plain[1].items() if k != "pcmapq"}


def test_without_gates_the_json_has_no_gates_block(plain):
    text, doc = plain
    assert "gates" not in doc and text == gates.to_json(doc)


def test_an_unknown_key_stops_before_any_work(tmp_path):
    out = tmp_path / "r.json"
    got = _eval("--json", str(out), "--fail-under", "harris.qualty=0.8")
    assert got.exit_code == 2 and not out.exists()
    line, = got.stderr.strip().splitlines()
    assert line.startswith("pcmapq: error: --fail-under: unknown key 'harris.qualty'")
