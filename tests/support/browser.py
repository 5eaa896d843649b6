"""Pages as a browser shows them (issue 41): an exported notebook or a page of the documentation
site opened in headless Chromium, offline. What the page's scripts drew (its DOM after they ran),
a screenshot, and every request it made that would leave the machine (Chromium's network log;
host names resolve nowhere, so such a request fails rather than reaching a network).

Used by tests/notebooks/test_notebooks.py and, on the built site, by .ci/docs:

    python tests/support/browser.py OUTDIR PAGE...   # screenshots in OUTDIR; exit 1 on a request

Chromium comes from the system (Debian's ``chromium``; .ci/run installs it where it can); without
it the tests that need it skip.
"""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

_NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
# Requests that leave the machine: any scheme but the page's own files, data: and blob: URLs and
# Chromium's internal pages.
_LOCAL = ("file:", "data:", "blob:", "chrome:", "chrome-error:", "about:", "devtools:")


def chromium() -> str | None:
    """The path of a Chromium (or Chrome) executable: $SPACAR_CHROMIUM, else the first on PATH."""
    given = os.environ.get("SPACAR_CHROMIUM")
    if given:
        return given
    return next((path for path in map(shutil.which, _NAMES) if path), None)


@dataclass
class Page:
    dom: str              # the document after its scripts ran
    requests: list[str]   # the URLs it asked for that would leave the machine
    screenshot: Path


def _run(args: list[str], timeout: float) -> str:
    out = subprocess.run(args, capture_output=True, text=True, timeout=timeout)
    if out.returncode != 0:
        raise RuntimeError(f"{' '.join(args[:2])} ... failed ({out.returncode}): {out.stderr[-2000:]}")
    return out.stdout


def _remote_requests(net_log: Path) -> list[str]:
    """The URLs the page asked for (the network log's jobs with the page as initiator; Chromium's
    own services, its clock and spelling dictionary, start theirs as "not an origin") that are
    not local."""
    text = net_log.read_text(encoding="utf-8", errors="replace")
    try:
        log = json.loads(text)
    except ValueError:  # the log's closing brackets are written at a clean exit only
        log = json.loads(text.rstrip().rstrip(",") + "]}")
    start_job = log["constants"]["logEventTypes"]["URL_REQUEST_START_JOB"]
    urls = {event["params"]["url"] for event in log["events"]
            if event.get("type") == start_job and "url" in event.get("params", {})
            and event["params"].get("initiator") != "not an origin"}
    return sorted(url for url in urls if not url.startswith(_LOCAL))


def open_page(page: Path, screenshot: Path, *, width: int = 1280, height: int = 3000,
              budget_ms: int = 15000, timeout: float = 120.0) -> Page:
    """Open ``page`` (a local HTML file) in headless Chromium with no network; its DOM after
    ``budget_ms`` of virtual time, the remote requests it made, and a screenshot of its top
    ``width`` × ``height`` pixels written to ``screenshot``."""
    exe = chromium()
    if exe is None:
        raise RuntimeError("no Chromium found (install Debian's chromium or set SPACAR_CHROMIUM)")
    url = Path(page).resolve().as_uri()
    with tempfile.TemporaryDirectory() as profile:
        common = [exe, "--headless", "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync",
                  "--disable-default-apps", "--host-resolver-rules=MAP * ~NOTFOUND",
                  f"--user-data-dir={profile}", f"--virtual-time-budget={budget_ms}"]
        net_log = Path(profile) / "net.json"
        dom = _run(common + [f"--log-net-log={net_log}", "--dump-dom", url], timeout)
        requests = _remote_requests(net_log)
        _run(common + [f"--window-size={width},{height}", "--hide-scrollbars",
                       f"--screenshot={Path(screenshot).resolve()}", url], timeout)
    return Page(dom=dom, requests=requests, screenshot=Path(screenshot))


def _main(argv: list[str]) -> int:
    if len(argv) < 2:
        print(__doc__)
        return 2
    if chromium() is None:
        print("browser: no Chromium (Debian's chromium, or SPACAR_CHROMIUM): the pages are not opened")
        return 0
    out = Path(argv[0])
    out.mkdir(parents=True, exist_ok=True)
    failed = False
    for name in argv[1:]:
        page = Path(name)
        shot = out / (re.sub(r"[^A-Za-z0-9]+", "_", str(page.with_suffix(""))).strip("_") + ".png")
        seen = open_page(page, shot)
        size = shot.stat().st_size
        print(f"browser: {page}: {len(seen.dom)} characters of DOM, screenshot {shot} ({size} bytes), "
              f"{len(seen.requests)} remote requests")
        for url in seen.requests:
            print(f"browser:   request leaving the machine: {url}")
        failed |= bool(seen.requests) or "<body" not in seen.dom
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1:]))
