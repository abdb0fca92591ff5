"""The committed env cards in docs/ match the env docstrings."""

from pathlib import Path

import pytest

import homing_gym
from homing_gym.envcard import card_filename, env_card

DOCS = Path(__file__).resolve().parents[2] / "docs" / "envs"


@pytest.mark.parametrize("env_id", homing_gym.ENV_IDS)
def test_env_card_is_current(env_id):
    page = DOCS / card_filename(env_id)
    assert page.is_file(), f"run: python -m homing_gym.envcard docs/envs"
    assert page.read_text() == env_card(env_id), "run: python -m homing_gym.envcard docs/envs"
    for section in ("## Action space", "## Observation space", "## Rewards",
                    "## Starting state", "## Episode end", "## Arguments", "## Version history"):
        assert section in page.read_text()


ROOT = Path(__file__).resolve().parents[2]
#: the longest a docs page may be: a page states the current state, its figures and the
#: command for each; history goes to CHANGELOG.md or docs/design-notes.md
MAX_PAGE_LINES = 500
MAX_README_LINES = 150


def test_no_docs_page_is_too_long():
    pages = sorted((ROOT / "docs").rglob("*.md"))
    assert pages, "no pages under docs/"
    too_long = {str(p.relative_to(ROOT)): n for p in pages
                if (n := len(p.read_text().splitlines())) > MAX_PAGE_LINES}
    assert not too_long, f"pages over {MAX_PAGE_LINES} lines (split them): {too_long}"


def test_readme_is_short_and_has_ci_test_command():
    lines = (ROOT / "README.md").read_text().splitlines()
    assert len(lines) <= MAX_README_LINES, f"README.md has {len(lines)} lines"
    # .ci/run runs "the README's test command": the README gives exactly that one
    ci = (ROOT / ".ci" / "run").read_text()
    command = "python -m pytest -q --run-slow"
    assert command in ci
    assert sum(command in line for line in lines) == 1


def test_citation_file_matches_the_package():
    tomllib = pytest.importorskip("tomllib")  # Python 3.11+

    yaml = pytest.importorskip("yaml")
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert cff["cff-version"] == "1.2.0"
    assert cff["version"] == project["version"]
    assert cff["license"] == project["license"]["text"]
    for key in ("title", "authors", "message", "date-released"):
        assert cff[key]
