"""The guide's examples run as written: every `pcmapq` command of the shell blocks of the
README, docs/getting-started.md and docs/commands/*.md (with the `echo ... > FILE` lines that
make their inputs) and their Python block, from a folder laid out like the repository beside
../shared; the blocks reading ../shared/data skip where it is absent. The sample's verdict shown
in the README is the one the command prints."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest
from typer.testing import CliRunner

from pcmapq.cli import app
from pcmapq.settings import MatchingConfig
from testkit.paths import REPO, SHARED_DATA

README = (REPO / "README.md").read_text()
#: The pages whose examples run: the README, getting started and one page per command.
PAGES = [REPO / "README.md", REPO / "docs" / "getting-started.md",
         *sorted((REPO / "docs" / "commands").glob("*.md"))]
#: Fenced blocks of every page: (language, body).
BLOCKS = [block for page in PAGES
          for block in re.findall(r"^```(\w*)\n(.*?)^```", page.read_text(), flags=re.S | re.M)]


def commands(body: str) -> list[str]:
    """The commands of a shell block: continuation lines joined, comments dropped, and of
    `A && B` the parts that are pcmapq commands or echo lines (not the install and test
    commands)."""
    joined = re.sub(r"\\\n\s*", " ", body)
    out = []
    for line in joined.splitlines():
        for part in line.split(" && "):
            words = shlex.split(part, comments=True)
            if words and words[0] in ("pcmapq", "echo"):
                out.append(part)
    return out


SHELL = [commands(body) for lang, body in BLOCKS if lang in ("", "sh", "bash")]
SHELL = [block for block in SHELL if block]
PYTHON = [body for lang, body in BLOCKS if lang == "python"]


@pytest.fixture
def repo(tmp_path, monkeypatch) -> Path:
    """A working folder like the repository's: data/ and ../shared/data reachable as the
    README writes them; the examples' outputs land here."""
    work = tmp_path / "repo"
    work.mkdir()
    (work / "data").symlink_to(REPO / "data")
    (tmp_path / "shared").mkdir()
    (tmp_path / "shared" / "data").symlink_to(SHARED_DATA)
    monkeypatch.chdir(work)
    return work


def echo(words: list[str]) -> None:
    """`echo TEXT > FILE`, as the shell runs it."""
    split = words.index(">")
    Path(words[split + 1]).write_text(" ".join(words[1:split]) + "\n")


@pytest.mark.unit
def test_the_readme_has_examples():
    assert len(SHELL) >= 3 and len(PYTHON) == 1
    assert sum(len(block) for block in SHELL) >= 10
    assert any(SAMPLE_RUN in block for block in SHELL)


#: The sample's verdict as the README shows it.
SHOWN = re.search(r"^```text\n(.*?)^```", README, flags=re.S | re.M).group(1)
SAMPLE_RUN = "pcmapq eval data/sample/scan.ply data/sample/truth.png"


@pytest.mark.parametrize("block", [
    pytest.param(b, marks=[pytest.mark.realdata] if "../shared/data" in " ".join(b) else [],
                 id=f"{b[-1].split()[1]}-{i}") for i, b in enumerate(SHELL)])
def test_shell_examples_run_as_written(block, repo):
    if "../shared/data" in " ".join(block) and not SHARED_DATA.exists():
        pytest.skip(f"{SHARED_DATA} is absent (real data lives in ../shared/data)")
    for line in block:
        words = shlex.split(line, comments=True)
        if words[0] == "echo":
            echo(words)
            continue
        got = CliRunner().invoke(app, words[1:], env={"COLUMNS": "80"})
        assert got.exit_code == 0, f"{line}\n{got.stdout}{got.stderr}"
        if line == SAMPLE_RUN:
            assert got.stdout.split("\n\n")[0] + "\n" == SHOWN
    for word in " ".join(block).split():  # every file an example writes is there
        if word.endswith((".json", ".csv", ".png", ".html", ".ply", ".txt")) and \
                not word.startswith(("data/", "../")):
            assert (repo / word).stat().st_size > 0, word


@pytest.mark.parametrize("body", PYTHON, ids=["python"])
def test_python_example_runs_as_written(body, repo, capsys):
    exec(compile(body, "docs/getting-started.md", "exec"), {})  # its evaluate(...): the pipeline
    quality, accuracy = capsys.readouterr().out.split()
    assert 0.5 < float(quality) <= 1.0 and float(accuracy) > 0
    assert (repo / "result.json").stat().st_size > 0


API = (REPO / "docs" / "api.md").read_text()


def test_the_api_page_runs_as_written(repo, capsys):
    """docs/api.md's example: evaluate, inspect and track through `import pcmapq`, printing
    what the commands print."""
    body, = (b for lang, b in re.findall(r"^```(\w*)\n(.*?)^```", API, flags=re.S | re.M)
             if lang == "python")
    if not (SHARED_DATA / "carmen" / "fhw-corrected.log.gz").exists():
        pytest.skip("../shared/data/carmen is absent (real data lives in ../shared/data)")
    exec(compile(body, "docs/api.md", "exec"), {})
    out = capsys.readouterr().out.splitlines()
    n = len(MatchingConfig().detectors)  # a line per detector, then the yaw
    assert out[0].startswith("harris: quality ") and "occupied cells" in out[n + 1]
    scans = [int(line.split()[0]) for line in out[n + 2:]]
    assert scans[-1] == 488 and scans == sorted(scans)
