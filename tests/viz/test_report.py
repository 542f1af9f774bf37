"""The sizing report's page in headless Chromium (tests/viz/chromium.py), at 1400 x 900 as a
user opens it: the overall verdict and every joint's verdict row (joint, parts, pass/fail,
binding check, margin) lie inside the first screen (DOM geometry); the screenshot's pixels in a
failing joint's status cell are the fail colour and a passing one's the pass colour; the page
requests nothing but itself (its figures are data: URIs); printing gives a PDF with each
section on its own page.

The report: a UR5 (example-robot-data) along a smooth point-to-point motion with what-if
actuators on five joints, one motor too small for its joint (shoulder_lift_joint fails its
continuous torque), one motor without a datasheet (wrist_2_joint: not checked), wrist_3_joint
without an actuator. Chromium missing: the tests skip, unless ``CI=true`` where they fail.
"""

from __future__ import annotations

import base64
import io
import os

import armdyn as ad
import numpy as np
import pytest
from armdyn.sizing import make_motor
from chromium import Browser, chromium_path  # tests/viz/chromium.py (pytest's rootdir import)

from benchmarks import common

Image = pytest.importorskip("PIL.Image")
pytest.importorskip("matplotlib")

FAIL_RGB, PASS_RGB, UNCHECKED_RGB = (0xC6, 0x28, 0x28), (0x1B, 0x7F, 0x3B), (0xB2, 0x6A, 0x00)
WIDTH, HEIGHT = 1400, 900


def needs_chromium():
    if chromium_path() is None:
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail("chromium is missing in CI: .ci/run installs it (apt-get install chromium)")
        pytest.skip("chromium is not installed (apt-get install chromium); CI runs these tests")


def motor(name, cont, peak):
    return make_motor(
        name=name,
        torque_constant=0.1,
        resistance=0.5,
        voltage=48.0,
        no_load_speed=480.0,
        continuous_torque=cont,
        peak_torque=peak,
        max_speed=400.0,
        thermal_resistance=1.5,
        thermal_time_constant=40.0,
    )


def ur5_report():
    path = common.robot_urdf("ur5")
    assert path is not None, "example-robot-data is part of the test extra"
    model = ad.load_urdf(path)
    t = np.linspace(0.0, 2.0, 201)
    q0 = np.array([0.0, -1.2, 1.0, -0.5, 0.4, 0.0])
    q1 = np.array([1.2, -0.6, 0.4, -1.2, 1.0, 0.8])
    w = np.pi / 2.0
    s, sd, sdd = 0.5 - 0.5 * np.cos(w * t), 0.5 * w * np.sin(w * t), 0.5 * w * w * np.cos(w * t)
    dq = q1 - q0
    run = ad.trajectory_run(model, t, q0 + np.outer(s, dq), np.outer(sd, dq), np.outer(sdd, dq))
    spec = dict(gear_ratio=100.0, rotor_inertia=3e-5, efficiency=0.9)
    actuators = {
        "shoulder_pan_joint": dict(spec, motor=motor("EC-45 70W", 0.3, 1.2)),
        "shoulder_lift_joint": dict(spec, motor=motor("EC-45 70W", 0.3, 1.2)),
        "elbow_joint": dict(spec, motor=motor("EC-60 100W", 0.6, 2.5)),
        "wrist_1_joint": dict(spec, rotor_inertia=1e-5, motor=motor("EC-32 40W", 0.1, 0.4)),
        "wrist_2_joint": dict(spec, motor=make_motor(name="no datasheet", torque_constant=0.05)),
    }
    return ad.sizing_report(run, model, actuators=actuators)


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    report = ur5_report()
    return report, report.save(tmp_path_factory.mktemp("report"))


@pytest.fixture(scope="module")
def browser(page):
    needs_chromium()
    with Browser(WIDTH, HEIGHT) as b:
        # the viewport itself 1400 x 900 (--window-size counts the window's frame)
        b.call(
            "Emulation.setDeviceMetricsOverride",
            width=WIDTH,
            height=HEIGHT,
            deviceScaleFactor=1,
            mobile=False,
        )
        b.open(page[1])
        yield b


def png(data: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(data)).convert("RGB")).astype(int)


ROWS = """Array.from(document.querySelectorAll('tr.verdict-row')).map(tr => {
  const r = tr.getBoundingClientRect();
  const s = tr.querySelector('td.status').getBoundingClientRect();
  return {joint: tr.dataset.joint, status: tr.dataset.status, text: tr.innerText,
          top: r.top, bottom: r.bottom, left: r.left, right: r.right,
          cell: [s.left, s.top, s.right, s.bottom]};
})"""


def test_the_verdict_rows_are_in_the_first_screen(page, browser):
    report = page[0]
    assert browser.evaluate("[innerWidth, innerHeight]") == [WIDTH, HEIGHT]
    assert browser.evaluate("scrollY") == 0
    rows = browser.evaluate(ROWS)
    assert [r["joint"] for r in rows] == list(report.table.index)
    for r in rows:  # every row whole inside the 1400 x 900 viewport, the margin column too
        assert 0 <= r["top"] and r["bottom"] <= HEIGHT, r
        assert 0 <= r["left"] and r["right"] <= WIDTH, r
    overall = browser.evaluate(
        "(() => { const e = document.getElementById('overall'); const r = "
        "e.getBoundingClientRect(); return [e.dataset.status, e.innerText, r.bottom]; })()"
    )
    assert overall[0] == "fail" and "FAIL" in overall[1] and overall[2] <= HEIGHT


def test_the_rows_say_their_status_in_words(page, browser):
    """Readable without colour: the status cell's text is the status, the failing margin is
    marked; the statuses are the table's: ok, a margin < 1, or a check not made."""
    report = page[0]
    table = report.table
    rows = {r["joint"]: r for r in browser.evaluate(ROWS)}
    assert rows["shoulder_lift_joint"]["status"] == "fail"
    assert (
        "FAIL" in rows["shoulder_lift_joint"]["text"]
        and "\u2718 0." in rows["shoulder_lift_joint"]["text"]
    )
    assert rows["wrist_2_joint"]["status"] == "unchecked"
    assert "NOT CHECKED" in rows["wrist_2_joint"]["text"]
    for joint, r in rows.items():
        ok = bool(table.loc[joint, "ok"])
        assert (r["status"] == "pass") == ok, joint
        assert ("PASS" in r["text"]) == ok, joint
        assert ("FAIL" in r["text"]) == (r["status"] == "fail"), joint


def colour_share(image: np.ndarray, cell, rgb) -> float:
    x0, y0, x1, y1 = (round(v) for v in cell)
    box = image[y0 + 2 : y1 - 2, x0 + 2 : x1 - 2]
    near = np.all(np.abs(box - np.array(rgb)) <= 12, axis=-1)
    return float(near.mean())


def test_the_screenshot_shows_the_fail_colour_on_the_failing_joint(browser):
    image = png(browser.screenshot())
    assert image.shape[:2] == (HEIGHT, WIDTH)
    rows = {r["joint"]: r for r in browser.evaluate(ROWS)}
    # the cell's background is the colour, its text white: most of its pixels are the colour
    fail = colour_share(image, rows["shoulder_lift_joint"]["cell"], FAIL_RGB)
    assert fail > 0.6, fail
    assert colour_share(image, rows["shoulder_lift_joint"]["cell"], PASS_RGB) == 0.0
    for joint in ("shoulder_pan_joint", "elbow_joint", "wrist_1_joint", "wrist_3_joint"):
        assert colour_share(image, rows[joint]["cell"], PASS_RGB) > 0.6, joint
        assert colour_share(image, rows[joint]["cell"], FAIL_RGB) == 0.0, joint
    assert colour_share(image, rows["wrist_2_joint"]["cell"], UNCHECKED_RGB) > 0.3
    # the overall badge is the fail colour too
    badge = browser.evaluate(
        "(() => { const r = document.getElementById('overall').getBoundingClientRect(); "
        "return [r.left, r.top, r.right, r.bottom]; })()"
    )
    assert colour_share(image, badge, FAIL_RGB) > 0.5


def test_the_page_requests_nothing_but_itself(page, browser):
    urls = browser.requested_urls()
    assert urls[0] == "file://" + os.path.abspath(page[1])
    # the figures are embedded: data: URIs the page decodes itself, never a file or a host
    others = [u for u in urls[1:] if not u.startswith("data:image/png;base64,")]
    assert others == []
    n_images = browser.evaluate("document.images.length")
    assert n_images >= 11  # 6 torque + 5 motor envelopes + the thermal history
    assert browser.evaluate(
        "Array.from(document.images).every(i => i.complete && i.naturalWidth > 0)"
    )
    assert browser.evaluate("document.scripts.length") == 0
    assert browser.console_errors() == []


def test_print_to_pdf_puts_each_section_on_its_own_page(browser):
    browser.call("Emulation.setEmulatedMedia", media="print")
    try:
        breaks = browser.evaluate(
            "Array.from(document.querySelectorAll('section')).map(s => "
            "[s.id, getComputedStyle(s).breakBefore])"
        )
        inside = browser.evaluate(
            "getComputedStyle(document.getElementById('verdict-table')).breakInside"
        )
    finally:
        browser.call("Emulation.setEmulatedMedia", media="")
    assert breaks[0] == ["verdict", "auto"]
    assert all(b == "page" for _, b in breaks[1:]) and len(breaks) >= 6
    assert inside == "avoid"
    pdf = base64.b64decode(browser.call("Page.printToPDF", printBackground=True)["data"])
    assert pdf[:5] == b"%PDF-"
    import re

    pages = len(re.findall(rb"/Type\s*/Page[^s]", pdf))
    assert pages >= len(breaks), pages  # at least one page per section
