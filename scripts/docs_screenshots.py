"""Screenshots of a run's report.html and Meshcat replays for the docs (docs/images/*.png, palette PNG < 300 kB).

Usage: .venv/bin/python scripts/docs_screenshots.py out/demo [docs/images]
(out/demo: the folder of a `gift demo` run; needs chromium, chromium-driver and selenium, see scripts/setup.sh)
"""

from __future__ import annotations

import io
import json
import sys
import time
from pathlib import Path

from PIL import Image

from gift_experiments.browser import console_errors, open_page, start_chromium

MAX_BYTES = 300_000


def save(driver, path: Path, crop_height: int | None = None) -> None:
    img = Image.open(io.BytesIO(driver.get_screenshot_as_png())).convert("RGB")
    if crop_height:
        img = img.crop((0, 0, img.width, min(crop_height, img.height)))
    for colours in (256, 128, 64):
        buf = io.BytesIO()
        img.quantize(colours, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE).save(buf, "PNG", optimize=True)
        if buf.tell() < MAX_BYTES:
            break
    path.write_bytes(buf.getvalue())
    print(f"{path}: {img.width}x{img.height}, {buf.tell() / 1000:.0f} kB, {colours} colours")


def main(out: Path, images: Path) -> None:
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    images.mkdir(parents=True, exist_ok=True)
    intent = next(iter(json.loads((out / "results.json").read_text())["rq1"]))
    d = start_chromium()
    try:
        d.set_window_size(1280, 1000)
        open_page(d, out / "report.html")
        save(d, images / "report_html.png")
        d.execute_script(f"document.querySelector('#intent-{intent} table.objects').scrollIntoView()")
        d.execute_script("window.scrollBy(0, -40)")
        save(d, images / "report_objects.png", 820)
        dots = d.find_elements(By.CSS_SELECTOR, f'#intent-{intent} svg[data-plot="decisions"] circle.pt')
        d.execute_script("arguments[0].scrollIntoView({block: 'center'})", dots[-1])
        ActionChains(d).move_to_element(dots[-1]).perform()
        time.sleep(0.2)
        save(d, images / "report_plots.png", 820)
        assert not console_errors(d)
        d.set_window_size(1280, 760)
        for view, at in (("test", 2.5), ("demos", 2.5)):
            open_page(d, out / "views" / f"{intent}_{view}.html")
            time.sleep(at)
            save(d, images / f"meshcat_{view}.png")
    finally:
        d.quit()


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]) if len(sys.argv) > 2 else Path("docs/images"))
