"""The report in a real browser: renders cleanly, model text stays text, controls work."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from rover.report import build_report

pytestmark = [
    pytest.mark.browser,
    pytest.mark.skipif(not os.path.exists("/usr/bin/chromium"), reason="needs Debian chromium"),
]
pytest.importorskip("websockets")

INJECTION = "<script>document.title='pwned'</script>"
# sort the episode table by its last column (spread), twice: descending, then ascending
SORT = """(() => {
  const th = document.querySelector('table.episodes th:last-child');
  const col = () => Array.from(document.querySelectorAll('table.episodes tbody tr'))
      .map(r => parseFloat(r.lastElementChild.dataset.v));
  th.click(); const first = col(); th.click(); return [first, col()];
})()"""
TOGGLE = """(() => {
  const curve = document.querySelector('polyline.curve-0');
  const before = getComputedStyle(curve).display;
  document.querySelector('label[for="show-0"]').click();
  return [before, getComputedStyle(curve).display];
})()"""


def test_page_renders_without_errors_and_injection_stays_text(
    make_run, open_in_chromium, tmp_path: Path
) -> None:
    index = build_report(make_run(), tmp_path / "report")
    page = open_in_chromium(index, {"sort": SORT})
    assert page.errors == []
    assert page.broken_images == []
    assert page.title.startswith("rover report")
    assert page.scripts == 1  # the table sorter, nothing else
    assert "ORACLE OUTPUT — answers come from simulator ground truth, not a VLM" in page.text
    desc, asc = page.checks["sort"]
    assert desc == sorted(desc, reverse=True) and asc == sorted(asc) and len(asc) == 3
    assert page.screenshot[:8] == b"\x89PNG\r\n\x1a\n"
    (tmp_path / "screenshot.png").write_bytes(page.screenshot)

    episode = open_in_chromium(index.parent / "episodes" / "ep0.html", {"toggle": TOGGLE})
    assert episode.errors == [] and episode.broken_images == []
    assert "pwned" not in episode.title
    assert INJECTION in episode.text  # shown to the reader, as text
    assert episode.scripts == 0
    assert episode.checks["toggle"] == ["inline", "none"]  # a legend click hides the curve
