"""armdyn.animate: one self-contained HTML file (K3D's standalone viewer inlined).

The file is rendered in headless Chromium (offline: a proxy at a closed port; every request of
the page and of the workers it starts recorded through CDP, the browser's own traffic apart): it
loads with no external URL, the screenshot shows the robot (the pixels that change when the
robot's meshes are hidden through the viewer's ``getObjectById``), the robot moves when the
time changes, the play/pause toggle and the time slider work. The poses embedded
in the file are decoded in Python and checked against the joint-space kinematics
(``armdyn.frame_pose`` on ``result.q``). Chromium missing: the browser tests skip, unless
``CI=true`` where they fail.
"""

from __future__ import annotations

import base64
import io
import os
import re
import sys
import zlib
from pathlib import Path
from types import SimpleNamespace

import armdyn as ad
import numpy as np
import pytest
from armdyn import animation
from chromium import Browser, chromium_path  # tests/viz/chromium.py (pytest's rootdir import)
from scipy.spatial.transform import Rotation

from benchmarks import common

k3d = pytest.importorskip("k3d", reason="the viz extra (k3d) is part of the test extra")
msgpack = pytest.importorskip("msgpack")
Image = pytest.importorskip("PIL.Image")

FOLDER = (
    "Array.from(document.querySelectorAll('.lil-gui')).find("
    "g => g.querySelector(':scope > .lil-title')?.textContent === 'Animation')"
)
FRAME = "new Promise(r => requestAnimationFrame(() => requestAnimationFrame(() => r(1))))"
LOADED = f"K3DInstance.then(k => {FRAME})"


def needs_chromium():
    if chromium_path() is None:
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail("chromium is missing in CI: .ci/run installs it (apt-get install chromium)")
        pytest.skip("chromium is not installed (apt-get install chromium); CI runs these tests")


def snapshot(html: str) -> dict:
    """The viewer's data embedded in the page: zlib'd msgpack, base64 in ``var data = '...'``."""
    data = re.search(r"var data = '([^']*)';", html).group(1)
    return msgpack.unpackb(zlib.decompress(base64.b64decode(data)), strict_map_key=False)


def array(field: dict) -> np.ndarray:
    return np.frombuffer(field["data"], dtype=field["dtype"]).reshape(field["shape"])


def png(data: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(data)).convert("RGB")).astype(int)


@pytest.fixture(scope="module")
def ur5_run():
    path = common.robot_urdf("ur5")
    assert path is not None, "example-robot-data is part of the test extra"
    model = ad.load_urdf(path)
    # released from a bent pose: the arm falls and swings under gravity
    result = ad.simulate(model, 1.0, output_dt=0.01, q0=[0.3, -1.2, 1.0, -0.5, 0.4, 0.0])
    return model, result


@pytest.fixture(scope="module")
def ur5_html(ur5_run, tmp_path_factory):
    model, result = ur5_run
    out = animation.animate(model, result, tmp_path_factory.mktemp("anim") / "ur5.html", grid=False)
    return out


@pytest.fixture(scope="module")
def page(ur5_html):
    needs_chromium()
    with Browser(800, 600) as b:
        b.open(ur5_html)
        b.evaluate(LOADED)
        yield b


def test_file_holds_the_viewer_and_names_no_external_url(ur5_html):
    html = ur5_html.read_text(encoding="utf-8")
    # no script, stylesheet, image or module fetched from a URL
    assert not re.search(r"""(src|href)\s*=\s*["']?\s*(https?:)?//""", html, re.I)
    assert not re.search(r"""(import\s*\(|fetch\s*\(|importScripts\s*\()\s*["'`]https?:""", html)
    # the viewer's code is inlined (K3D's standalone bundle, zlib'd), not referenced
    assert "window.k3dCompressed = '" in html and "CreateK3DAndLoadBinarySnapshot" in html
    assert len(html) > 1_000_000


def test_page_loads_offline_with_no_request_beyond_the_file(page, ur5_html):
    """The page (and any worker or frame it starts) requests nothing but its own file and
    in-memory data. The browser's own traffic (its update and component checks, through the
    proxy) is not the page's and is not counted: the record is CDP's, of the page's targets."""
    page.evaluate(FRAME)
    urls = page.requested_urls()
    assert urls and urls[0] == ur5_html.resolve().as_uri()
    schemes = {u.split(":", 1)[0] for u in urls}
    assert schemes <= {"file", "data", "blob"}, [u[:80] for u in urls if not u.startswith("data:")]
    assert page.console_errors() == []
    # the record can fail: a fetch of the page reaches the network (the proxy sees it) and is
    # in the record; so is one made by a worker the page starts (a separate target)
    page.evaluate("fetch('https://example.org/probe').catch(() => 0)")
    assert "example.org" in page.proxy.hosts()
    assert "https://example.org/probe" in page.requested_urls()
    worker = (
        "new Promise(done => { const w = new Worker(URL.createObjectURL(new Blob(["
        "\"fetch('https://example.net/worker-probe').catch(() => 0)"
        '.finally(() => postMessage(1));"]))); w.onmessage = () => done(1); })'
    )
    page.evaluate(worker)
    assert any(s["type"] == "worker" for s in page.sessions), page.sessions
    assert "https://example.net/worker-probe" in page.requested_urls()
    assert "example.net" in page.proxy.hosts()


def test_embedded_poses_equal_the_kinematics(ur5_run, ur5_html):
    model, result = ur5_run
    snap = snapshot(ur5_html.read_text(encoding="utf-8"))
    shown = animation.frame_rows(result.t, 30.0)
    # 30 fps of a 100 Hz output: rows 0, 4, 8, ... (0.04 s >= 1/30 s), the last one included
    assert list(shown[:3]) == [0, 4, 8] and shown[-1] == len(result.t) - 1
    links = {}
    for obj in snap["objects"]:
        links.setdefault(obj["name"], []).append(obj["model_matrix"])
    assert set(links) == {
        "base_link",
        "shoulder_link",
        "upper_arm_link",
        "forearm_link",
        "wrist_1_link",
        "wrist_2_link",
        "wrist_3_link",
    }
    checked = 0
    for link, matrices in links.items():
        for mm in matrices:
            if "data" in mm:  # a link on the ground: one constant matrix
                ref = ad.frame_pose(model, result.q[0], link)
                assert np.array_equal(ref, ad.frame_pose(model, result.q[-1], link))
                series = {result.t[0]: array(mm)}
            else:
                series = {float(k): array(v) for k, v in mm.items()}
                assert sorted(series) == list(result.t[shown])
            for t, got in series.items():
                i = int(np.searchsorted(result.t, t))
                ref = ad.frame_pose(model, result.q[i], link)
                # stored as float32: equal to the kinematics to the float32 rounding (<= half
                # an ulp) plus 1e-9 for the Cartesian vs joint-space evaluation
                ulp = np.spacing(np.abs(ref).astype(np.float32)).astype(float)
                assert np.all(np.abs(got.astype(float) - ref) <= 0.5 * ulp + 1e-9), (link, t)
                checked += 1
    assert checked >= 6 * len(shown)


def test_screenshot_shows_the_robot_and_its_motion(page, ur5_html, ur5_run):
    _, result = ur5_run
    snap = snapshot(ur5_html.read_text(encoding="utf-8"))
    ids = [o["id"] for o in snap["objects"]]
    shown = png(page.screenshot())

    # the viewer's getObjectById gives each mesh's three.js object
    def show(visible: bool):
        each = f"{ids}.forEach(i => {{ k.getObjectById(i).visible = {str(visible).lower()} }})"
        page.evaluate(f"K3DInstance.then(k => {{ {each}; k.render(); return {FRAME} }})")

    show(False)
    hidden = png(page.screenshot())
    show(True)
    assert np.array_equal(png(page.screenshot()), shown)  # nothing else changed
    # without the robot the view is the plain white background (the panel and the axes
    # helper in the corners aside)
    h, w = hidden.shape[:2]
    centre = (slice(h // 8, 7 * h // 8), slice(w // 8, 5 * w // 8))
    assert np.all(hidden[centre] >= 250)
    robot = np.any(np.abs(shown - hidden) > 30, axis=2)
    assert robot.mean() > 0.01, f"only {robot.mean():.4f} of the pixels show the robot"
    # at the end of the run the arm has fallen elsewhere: other pixels
    page.evaluate(f"K3DInstance.then(k => {{ k.setTime({result.t[-1]}); return {FRAME} }})")
    later = png(page.screenshot())
    moved = np.any(np.abs(later - shown) > 30, axis=2)
    assert moved.mean() > 0.01
    page.evaluate(f"K3DInstance.then(k => {{ k.setTime({result.t[0]}); return {FRAME} }})")
    if os.environ.get("ARMDYN_WRITE_FIGURES") == "1":
        figure = Path(__file__).parents[2] / "docs" / "figures" / "animation_ur5.png"
        Image.fromarray(shown.astype(np.uint8)).save(figure, optimize=True)


def test_play_pause_and_time_slider(page, ur5_run):
    _, result = ur5_run
    controls = page.evaluate(
        f"Array.from({FOLDER}.querySelectorAll('.lil-controller')).map("
        "c => [c.querySelector('.lil-name').textContent, c.querySelector('.lil-slider') !== null])"
    )
    assert ["time", True] in controls and ["Play loop", False] in controls
    # the slider spans the run
    info = page.evaluate("K3DInstance.then(k => k.getTimeSeriesInfo())")
    assert info["min"] == result.t[0] and info["max"] == result.t[-1]
    button = f"{FOLDER}.querySelector('.lil-function button')"
    time_now = "K3DInstance.then(k => k.parameters.time)"
    t0 = page.evaluate(time_now)
    assert page.evaluate(f"(() => {{ {button}.click(); return {button}.textContent }})()") == (
        "Stop loop"
    )
    for _ in range(10):  # playing: the time moves within 10 frames (stop once it has)
        page.evaluate(FRAME)
        if page.evaluate(time_now) != t0:
            break
    assert page.evaluate(time_now) != t0  # playing
    assert page.evaluate(f"(() => {{ {button}.click(); return {button}.textContent }})()") == (
        "Play loop"
    )
    paused = page.evaluate(time_now)
    for _ in range(10):
        page.evaluate(FRAME)
    assert page.evaluate(time_now) == paused  # paused
    # the slider sets the time
    page.evaluate(
        f"(() => {{ const c = Array.from({FOLDER}.querySelectorAll('.lil-controller')).find("
        "c => c.querySelector('.lil-name').textContent === 'time'); const i = "
        "c.querySelector('input'); i.value = '0.5'; i.dispatchEvent(new Event('input')); })()"
    )
    assert page.evaluate(time_now) == 0.5


# ---------------------------------------------------------------------------------------------
# geometry, without a browser


def test_urdf_shapes_origins_and_colours(tmp_path):
    urdf = """<robot name="r">
      <material name="red"><color rgba="1 0 0 1"/></material>
      <link name="a">
        <visual><origin xyz="1 2 3" rpy="0 0 1.5707963267948966"/>
          <geometry><box size="0.2 0.4 0.6"/></geometry><material name="red"/></visual>
        <visual><geometry><cylinder radius="0.1" length="0.5"/></geometry>
          <material name="m"><color rgba="0 0.5 1 1"/></material></visual>
        <visual><geometry><sphere radius="0.25"/></geometry></visual>
      </link>
    </robot>"""
    box, cyl, sph = animation.urdf_visuals(urdf)
    # box rotated 90 deg about z: its x extent (0.2) lies along world y
    assert np.allclose(box.vertices.min(0), [1 - 0.2, 2 - 0.1, 3 - 0.3])
    assert np.allclose(box.vertices.max(0), [1 + 0.2, 2 + 0.1, 3 + 0.3])
    assert box.colour == (1.0, 0.0, 0.0) and cyl.colour == (0.0, 0.5, 1.0)
    r = np.hypot(cyl.vertices[:, 0], cyl.vertices[:, 1])
    assert np.isclose(r.max(), 0.1) and np.allclose(np.abs(cyl.vertices[:, 2]), 0.25)
    assert np.allclose(np.linalg.norm(sph.vertices, axis=1), 0.25)
    assert sph.colour == animation._DEFAULT_COLOUR


def test_mesh_paths_resolve_and_scale(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    pkg = tmp_path / "share" / "mypkg"
    (pkg / "meshes").mkdir(parents=True)
    (pkg / "urdf").mkdir()
    cube = trimesh.creation.box(extents=(1.0, 1.0, 1.0))
    cube.export(pkg / "meshes" / "cube.stl")
    cube.export(pkg / "meshes" / "cube.obj")
    urdf = pkg / "urdf" / "r.urdf"
    urdf.write_text(
        """<robot name="r"><link name="a">
        <visual><geometry><mesh filename="package://mypkg/meshes/cube.stl" scale="2 1 1"/>
        </geometry></visual>
        <visual><geometry><mesh filename="../meshes/cube.obj"/></geometry></visual>
        </link></robot>"""
    )
    stl, obj = animation.urdf_visuals(urdf)
    assert np.allclose(stl.vertices.max(0), [1.0, 0.5, 0.5])
    assert np.allclose(obj.vertices.max(0), [0.5, 0.5, 0.5])
    # a missing mesh names the link, the file and where it looked
    urdf.write_text(
        '<robot name="r"><link name="a"><visual><geometry><mesh filename="package://mypkg/'
        'meshes/gone.stl"/></geometry></visual></link></robot>'
    )
    with pytest.raises(ad.UrdfError, match=r"link 'a'.*gone\.stl.*not found.*looked at"):
        animation.urdf_visuals(urdf)


def test_dae_meshes_of_example_robot_data_load_in_the_link_frame():
    path = common.robot_urdf("ur5")
    visuals = [v for v in animation.urdf_visuals(path) if v.link == "upper_arm_link"]
    assert len(visuals) >= 1
    pts = np.concatenate([v.vertices for v in visuals])
    # the UR5 upper arm runs 0.425 m along its link z axis (the forearm joint at z = 0.425)
    assert -0.07 < pts[:, 2].min() < 0 and 0.425 < pts[:, 2].max() < 0.5


def test_inertia_box_is_the_uniform_box_of_that_inertia():
    m, a, b, c = 2.0, 0.3, 0.5, 1.1
    inertia = m / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])
    rot = animation._rpy_matrix((0.3, -0.7, 1.9))
    ext, axes = animation.inertia_box(m, rot @ inertia @ rot.T)
    assert np.allclose(sorted(ext), [a, b, c], rtol=1e-12)
    # its axes are the body's rotated axes
    k = int(np.argmax(ext))
    assert np.isclose(abs(axes[:, k] @ rot[:, 2]), 1.0)


def test_builder_model_draws_inertia_boxes_at_the_bodies(tmp_path):
    # a double pendulum of rods along their body z axes; a frame at each centre of mass gives
    # the reference pose through frame_pose_cartesian
    yhat = np.array([0.0, 1.0, 0.0])
    b = ad.ModelBuilder()
    rod = np.diag([1 / 12 * (1 + 3 * 0.0004), 1 / 12 * (1 + 3 * 0.0004), 0.5 * 0.0004])
    b.add_body("l1", 1.0, rod, position=(0, 0, -0.5))
    b.add_body("l2", 1.0, rod, position=(0, 0, -1.5))
    b.add_revolute("shoulder", "ground", "l1", (0, 0, 0), yhat)
    b.add_revolute("elbow", "l1", "l2", (0, 0, -1.0), yhat)
    b.add_frame("c1", "l1", position=(0, 0, -0.5))
    b.add_frame("c2", "l2", position=(0, 0, -1.5))
    model = b.finalize()
    result = ad.simulate(model, 0.5, output_dt=0.05, q0=[0.5, -0.3])
    out = animation.animate(model, result, tmp_path / "p.html", fps=10)
    snap = snapshot(out.read_text(encoding="utf-8"))
    boxes = [o for o in snap["objects"] if o["name"] in ("l1", "l2")]
    assert len(boxes) >= 2
    shown = animation.frame_rows(result.t, 10.0)
    for obj in boxes:
        frame = {"l1": "c1", "l2": "c2"}[obj["name"]]
        for k, v in obj["model_matrix"].items():
            i = int(np.searchsorted(result.t, float(k)))
            ref = ad.frame_pose_cartesian(model, result.u[i], frame)
            ulp = np.spacing(np.abs(ref).astype(np.float32)).astype(float)
            assert np.all(np.abs(array(v) - ref) <= 0.5 * ulp + 1e-9)
        assert sorted(float(k) for k in obj["model_matrix"]) == list(result.t[shown])
    # the first body's box: 1 m along its z axis (the rod's length)
    verts = array(boxes[0]["vertices"])
    assert np.isclose(np.ptp(verts[:, 2]), 1.0, rtol=1e-6)


def test_bad_input_raises_naming_the_culprit(ur5_run, tmp_path, monkeypatch):
    model, result = ur5_run
    with pytest.raises(ValueError, match="fps must be a positive number"):
        animation.animate(model, result, tmp_path / "x.html", fps=0)
    other = ad.load_urdf(common.robot_urdf("panda"))
    with pytest.raises(ad.ModelError, match=r"result\.u has shape .* the model needs"):
        animation.animate(other, result, tmp_path / "x.html")
    with pytest.raises(ad.UrdfError, match=r"are not frames of the model"):
        animation.animate(model, result, tmp_path / "x.html", urdf=common.robot_urdf("panda"))
    t, u = result.t, result.u
    for bad, match in [
        (SimpleNamespace(t=t[::-1], u=u), r"result\.t is not increasing at row 1"),
        (SimpleNamespace(t=t, u=np.where(t[:, None] > 0.5, np.nan, u)), r"non-finite .* row 51"),
        (SimpleNamespace(t=t[:0], u=u[:0], error="boom"), r"no rows \(boom\)"),
        (SimpleNamespace(t=t), r"needs times t .* got SimpleNamespace"),
        (SimpleNamespace(t=t, q=result.q[:, :5]), r"result\.q has shape \(101, 5\)"),
    ]:
        with pytest.raises(ad.ModelError, match=match):
            animation.animate(model, bad, tmp_path / "x.html")
    with pytest.raises(ValueError, match="time must be a finite number"):
        animation.animate(model, result, tmp_path / "x.html", time=float("nan"))
    assert not (tmp_path / "x.html").exists()
    monkeypatch.setitem(sys.modules, "k3d", None)
    with pytest.raises(ImportError, match=r"pip install 'armdyn\[viz\]'"):
        ad.animate(model, result, tmp_path / "x.html")


def test_links_without_visual_are_drawn_as_inertia_boxes(tmp_path):
    urdf = """<robot name="r">
      <link name="base"><visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual></link>
      <link name="arm">
        <inertial><origin xyz="0.25 0 0"/><mass value="2"/>
          <inertia ixx="0.001" iyy="0.05" izz="0.05" ixy="0" ixz="0" iyz="0"/></inertial>
      </link>
      <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
        <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="10" velocity="5"/></joint>
    </robot>"""
    model = ad.load_urdf(urdf)
    result = ad.simulate(model, 0.3, output_dt=0.1, q0=[0.4])
    out = animation.animate(model, result, tmp_path / "r.html")
    objs = snapshot(out.read_text(encoding="utf-8"))["objects"]
    assert [o["name"] for o in objs] == ["base", "arm", "arm"]  # box, then its joint rod
    box = objs[1]
    # the uniform box of that inertia: 0.5 m long (I_yy = m L^2 / 12 + ...), along body x
    verts = array(box["vertices"])
    assert np.isclose(np.ptp(verts[:, 0]), np.sqrt(6 * (0.05 + 0.05 - 0.001) / 2), rtol=1e-6)
    for k, v in box["model_matrix"].items():
        i = int(np.searchsorted(result.t, float(k)))
        ref = np.eye(4)
        # scipy's quaternion is scalar last
        ref[:3, :3] = Rotation.from_quat(result.u[i, [4, 5, 6, 3]]).as_matrix()
        ref[:3, 3] = result.u[i, :3]
        ulp = np.spacing(np.abs(ref).astype(np.float32)).astype(float)
        assert np.all(np.abs(array(v) - ref) <= 0.5 * ulp + 1e-9)


def test_joint_space_trajectory_run(tmp_path):
    # a planned motion (trajectory_run: t and q only) is drawn from q through state_from_joints
    model = ad.load_urdf(common.robot_urdf("ur5"))
    t = np.linspace(0.0, 1.0, 21)
    q = np.outer(np.sin(np.pi * t), [0.5, -0.8, 1.1, 0.3, -0.4, 0.9])
    run = ad.trajectory_run(model, t, q, np.gradient(q, t, axis=0), np.zeros_like(q))
    out = animation.animate(model, run, tmp_path / "plan.html", fps=10)
    objs = snapshot(out.read_text(encoding="utf-8"))["objects"]
    wrist = next(o for o in objs if o["name"] == "wrist_3_link")
    assert sorted(float(k) for k in wrist["model_matrix"]) == list(t[::2])
    for k, v in wrist["model_matrix"].items():
        ref = ad.frame_pose(model, q[int(np.searchsorted(t, float(k)))], "wrist_3_link")
        ulp = np.spacing(np.abs(ref).astype(np.float32)).astype(float)
        assert np.all(np.abs(array(v) - ref) <= 0.5 * ulp + 1e-9)


def test_dae_units_mirroring_scale_and_bad_sizes(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    # the UR5 upper arm declared in millimetres: <unit meter="0.001"> scales it as RViz does
    dae = common.robot_urdf("ur5").parents[1] / "meshes" / "ur5" / "visual" / "upperarm.dae"
    text = dae.read_text(encoding="utf-8")
    assert text.count('<unit name="meter" meter="1"/>') == 1
    (tmp_path / "mm.dae").write_text(text.replace('meter="1"', 'meter="0.001"'))
    cube = trimesh.creation.box(extents=(1.0, 2.0, 3.0))
    cube.export(tmp_path / "cube.stl")
    urdf = tmp_path / "r.urdf"
    urdf.write_text(
        """<robot name="r"><link name="a">
        <visual><geometry><mesh filename="upperarm.dae"/></geometry></visual>
        <visual><geometry><mesh filename="mm.dae"/></geometry></visual>
        <visual><geometry><mesh filename="cube.stl" scale="1 -1 1"/></geometry></visual>
        </link></robot>""".replace("upperarm.dae", str(dae))
    )
    visuals = animation.urdf_visuals(urdf)
    n = (len(visuals) - 1) // 2  # the pieces (materials) of each DAE
    assert len(visuals) == 2 * n + 1
    for metres, mm in zip(visuals[:n], visuals[n : 2 * n], strict=True):
        assert np.allclose(mm.vertices, 1e-3 * metres.vertices, rtol=1e-12, atol=0)
    # the mirrored cube keeps its triangles facing out (positive enclosed volume)
    mirrored = visuals[-1]
    assert np.isclose(trimesh.Trimesh(mirrored.vertices, mirrored.faces).volume, 6.0)
    for shape in ('<box size="0.1 -0.1 0.1"/>', '<sphere radius="0"/>'):
        with pytest.raises(ad.UrdfError, match=r"link 'a' <(box size|sphere radius)>.*positive"):
            animation.urdf_visuals(
                f'<robot name="r"><link name="a"><visual><geometry>{shape}</geometry></visual>'
                "</link></robot>"
            )
