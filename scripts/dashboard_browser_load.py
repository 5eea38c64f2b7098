#!/usr/bin/python3
"""The page under the fleet's load (docs/dashboard.md, "Measured"): headless Chromium opens the fleet page and
one cell's page of a running dashboard for SECONDS each and reports the events it handled per second and the
time its script spent on each (p50, p99, max), and the screen's frame rate. Usage (scripts/dashboard_load.sh
calls it): dashboard_browser_load.py PORT CELL SECONDS"""

import sys
import time

from selenium import webdriver
from selenium.webdriver.chrome.service import Service

port, cell, seconds = int(sys.argv[1]), sys.argv[2], float(sys.argv[3])
options = webdriver.ChromeOptions()
for a in ("--headless=new", "--no-sandbox", "--disable-gpu", "--window-size=1500,1000"):
    options.add_argument(a)
browser = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)
try:
    for name, url in (("fleet page", f"http://127.0.0.1:{port}/"), (f"cell page ({cell})", f"http://127.0.0.1:{port}/#/cell/{cell}")):
        browser.get(url)
        time.sleep(5)  # the first events and plots
        browser.execute_script(
            "window.robodamp.handlerMs = []; window.robodamp.events0 = window.robodamp.events;"
            "window.robodamp.frames = 0; (function f() { window.robodamp.frames++; requestAnimationFrame(f); })();")
        time.sleep(seconds)
        r = browser.execute_script("return {ms: window.robodamp.handlerMs, events: window.robodamp.events - window.robodamp.events0,"
                                   " frames: window.robodamp.frames, tiles: document.querySelectorAll('.tile').length}")
        ms = sorted(r["ms"])
        pick = lambda q: ms[min(len(ms) - 1, int(q * len(ms)))] if ms else float("nan")
        print(f"{name}: {r['tiles']} tiles, {r['events'] / seconds:.1f} events/s, script per event p50 {pick(0.5):.1f} ms, "
              f"p99 {pick(0.99):.1f} ms, max {ms[-1] if ms else float('nan'):.1f} ms; {r['frames'] / seconds:.0f} frames/s")
finally:
    browser.quit()
