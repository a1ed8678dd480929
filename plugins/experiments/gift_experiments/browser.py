"""Headless Chromium through selenium and the OS's chromedriver (``apt-get install chromium chromium-driver``
and ``pip install selenium``, both done by scripts/setup.sh's test set): the browser tests of report.html and
the Meshcat replays, and the screenshots of the docs (``scripts/docs_screenshots.py``)."""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

from gift.core.errors import GiftError

#: Flags for a machine without network: no background traffic (updates, sync, safe browsing, first-run pages).
FLAGS = ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run", "--disable-default-apps",
         "--hide-scrollbars", "--window-size=1280,900")


def start_chromium():
    """A selenium Chrome driver on the OS's chromium, with a fresh profile; a clear error when not installed."""
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
    except ImportError:
        raise GiftError("selenium is needed for the browser: pip install selenium==4.51.0 (scripts/setup.sh)") from None

    binary = shutil.which("chromium") or shutil.which("chromium-browser")
    driver = shutil.which("chromedriver")
    if not binary or not driver:
        raise GiftError("headless Chromium and its driver are needed: apt-get install chromium chromium-driver "
                    "(scripts/setup.sh installs them)")
    opts = webdriver.ChromeOptions()
    opts.binary_location = binary
    for flag in FLAGS + (f"--user-data-dir={tempfile.mkdtemp(prefix='gift-chromium-')}",):
        opts.add_argument(flag)
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    return webdriver.Chrome(service=Service(driver), options=opts)


def open_page(driver, path_or_url: Path | str) -> None:
    """Open a file (or URL) and drop the console messages of earlier pages."""
    url = path_or_url if isinstance(path_or_url, str) else Path(path_or_url).resolve().as_uri()
    driver.get(url)
    driver.get_log("browser")  # clears what was logged before


def console_errors(driver) -> list[dict]:
    """Console entries of level SEVERE (errors, failed loads) since the last call."""
    return [e for e in driver.get_log("browser") if e.get("level") == "SEVERE"]


def network_fetches(driver) -> list[str]:
    """Resources the page fetched over the network (http, https, ws): none for a self-contained page."""
    names = driver.execute_script("return performance.getEntriesByType('resource').map(e => e.name)")
    return [n for n in names if n.split(":", 1)[0] in ("http", "https", "ws", "wss")]
