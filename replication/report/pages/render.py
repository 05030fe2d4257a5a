"""Jinja2 rendering of the report pages (self-contained: no script, font or style from outside),
and a headless browser's view of a rendered page."""

import shutil
import subprocess
import tempfile
from pathlib import Path

import pandas as pd
from jinja2 import Environment, PackageLoader, select_autoescape
from markupsafe import Markup

from replication import atomic

ENVIRONMENT = Environment(
    loader=PackageLoader("replication.report.pages", "templates"),
    autoescape=select_autoescape(["html", "htm", "xml", "html.j2"]),  # the templates are *.html.j2: escape every value
)
BROWSERS = ("chromium", "chromium-browser", "google-chrome", "chrome")


def render(template: str, **context) -> str:
    return ENVIRONMENT.get_template(template).render(**context)


def html_table(table: pd.DataFrame) -> Markup:
    return Markup(table.to_html(index=False, escape=True, border=0, na_rep=""))


def browser() -> str | None:
    """A headless-capable Chromium on the PATH (Debian: ``apt-get install chromium``), or None."""
    return next((path for path in map(shutil.which, BROWSERS) if path), None)


def open_in_browser(page: Path, screenshot: Path | None = None, size=(1280, 2000), timeout: float = 60):
    """Load ``page`` in headless Chromium: its DOM after scripts ran, console messages, and a screenshot.

    Returns ``{"dom": str, "console": [str], "screenshot": Path | None}``;
    every line the page wrote to its console is in ``console`` (the pages
    write nothing unless something is wrong, a figure that did not load, say).
    Raises FileNotFoundError when no Chromium is installed.
    """
    binary = browser()
    if binary is None:
        raise FileNotFoundError("no Chromium on the PATH: apt-get install chromium")
    command = [
        binary, "--headless", "--disable-gpu", "--no-sandbox", "--hide-scrollbars", "--enable-logging=stderr",
        "--v=0", f"--window-size={size[0]},{size[1]}", "--dump-dom",
    ]
    url = Path(page).resolve().as_uri()
    with tempfile.TemporaryDirectory(prefix="chromium-") as profile:  # a fresh profile, nothing left in ~
        shot = Path(profile) / "screenshot.png"  # taken here, then put in place whole (replication.atomic)
        taking = [f"--screenshot={shot}"] if screenshot is not None else []
        done = subprocess.run([*command, *taking, f"--user-data-dir={profile}", url], capture_output=True,
                              text=True, timeout=timeout)
        if screenshot is not None and done.returncode == 0 and shot.exists():
            atomic.save(screenshot, lambda tmp: shutil.copyfile(shot, tmp))
    console = [line.split("] ", 1)[-1] for line in done.stderr.splitlines() if ":CONSOLE" in line]
    if done.returncode != 0:
        raise RuntimeError(f"{binary} exited {done.returncode}: {done.stderr[-2000:]}")
    return {"dom": done.stdout, "console": console, "screenshot": screenshot}
