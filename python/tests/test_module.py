"""The module against the CLI on the same input: maps, matches and localization results must be equal."""
import json
import os
import pathlib
import signal
import subprocess
import sys
import tempfile
import time

import numpy as np
import pytest

import vmap
from conftest import CLI, SHARED, STRETCH, VIDEO, map_json, needs_shared, run_cli

# Fields that differ between two runs of the same build: the wall time and what records it.
RUN_FIELDS = {"seconds"}


def without_run_fields(value):
    if isinstance(value, dict):
        return {k: without_run_fields(v) for k, v in value.items() if k not in RUN_FIELDS}
    if isinstance(value, list):
        return [without_run_fields(v) for v in value]
    return value


def test_build_map_writes_the_cli_map(maps):
    cli_dir, module_dir, built = maps
    cli, module = map_json(cli_dir), map_json(module_dir)
    assert without_run_fields(module) == without_run_fields(cli)
    assert (module_dir / "correspondences.bin").read_bytes() == (cli_dir / "correspondences.bin").read_bytes()
    for key in cli["key_images"]:
        assert (module_dir / key["image"]).read_bytes() == (cli_dir / key["image"]).read_bytes()
    assert built.num_frames == cli["num_frames"] == len(range(0, 60, 2))
    assert len(built.key_images) == cli["num_key_images"] and built.quality == cli["quality"]
    assert built.camera_mask is None and "camera_mask" not in cli["input"]


def test_a_host_programs_locale_changes_no_number(maps, tmp_path):
    """Python's locale.setlocale(LC_ALL, "") under a locale with a decimal comma: the camera's numbers are read as
    written and the map is the CLI's (k1 was read as -7 instead of -0.0076, and the report's numbers had commas)."""
    cli_dir, _, _ = maps
    locales = tmp_path / "locales"
    locales.mkdir()
    made = subprocess.run(["localedef", "-i", "de_DE", "-f", "UTF-8", str(locales / "de_DE.UTF-8")],
                          capture_output=True)
    if made.returncode != 0:
        pytest.skip("localedef cannot make de_DE.UTF-8 here")
    camera = ",".join(str(v) for v in map_json(cli_dir)["input"]["camera"]["params"])
    program = (f"import locale, vmap\n"
               f"locale.setlocale(locale.LC_ALL, '')\n"
               f"assert locale.localeconv()['decimal_point'] == ',', locale.localeconv()\n"
               f"vmap.build_map({str(VIDEO)!r}, {str(tmp_path / 'map')!r}, camera={camera!r}, report=True, "
               f"**{STRETCH!r})\n")
    env = dict(os.environ, LOCPATH=str(locales), LC_ALL="de_DE.UTF-8")
    run = subprocess.run([sys.executable, "-c", program], env=env, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    cli, module = map_json(cli_dir), map_json(tmp_path / "map")
    assert module["input"]["camera"]["params"] == cli["input"]["camera"]["params"]
    assert without_run_fields(module["links"]) == without_run_fields(cli["links"])
    report = (tmp_path / "map" / "report.html").read_text()
    import re
    assert not re.search(r'data-[a-z-]+="-?[0-9]+,[0-9]', report), "a number with a decimal comma in the report"


def write_grey_png(path, pixels):
    """An 8-bit grey PNG of a uint8 HxW array (zlib and the PNG chunks; no imaging library needed)."""
    import struct
    import zlib

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    height, width = pixels.shape
    rows = b"".join(b"\x00" + pixels[y].astype(np.uint8).tobytes() for y in range(height))
    header = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows)) +
                     chunk(b"IEND", b""))


def test_a_camera_mask_is_kept_as_the_cli_keeps_it(tmp_path):
    needs_shared()
    mask = np.full((480, 640), 255, dtype=np.uint8)
    mask[:, :160] = 0
    write_grey_png(tmp_path / "mask.png", mask)
    cli_dir, module_dir = tmp_path / "cli_map", tmp_path / "module_map"
    run_cli("build", VIDEO, "-o", cli_dir, "--camera-mask", tmp_path / "mask.png",
            *[f"--{k}={v}" for k, v in STRETCH.items()])
    vmap.build_map(str(VIDEO), module_dir, camera_mask=str(tmp_path / "mask.png"), **STRETCH)
    assert without_run_fields(map_json(module_dir)) == without_run_fields(map_json(cli_dir))
    assert map_json(cli_dir)["input"]["camera_mask"] == "camera_mask.png"
    assert (module_dir / "camera_mask.png").read_bytes() == (cli_dir / "camera_mask.png").read_bytes()
    kept = vmap.read_map(module_dir).camera_mask
    assert kept.shape == (480, 640) and kept.dtype == np.uint8
    np.testing.assert_array_equal(kept, mask)
    assert vmap.read_map(module_dir).key_images[0].num_features > 0


def test_a_key_image_replaced_after_read_map_is_refused_not_decoded(maps, tmp_path):
    # A map rebuilt into the folder of one a program holds: the old links must not be paired with new images, and
    # a file announcing 32000 x 32000 pixels must not be decoded (a gigabyte).
    import shutil
    cli_dir, _, _ = maps
    copy = tmp_path / "map"
    shutil.copytree(cli_dir, copy)
    m = vmap.read_map(copy)
    width, height = map_json(copy)["input"]["frame_size"]
    key_file = copy / m.key_images[0].image_file
    write_grey_png(key_file, np.zeros((height // 2, width // 2), dtype=np.uint8))
    with pytest.raises(vmap.Error, match="not the map's frame size .*changed since the map was read"):
        m.key_images[0].gray
    data = bytearray(key_file.read_bytes())
    data[16:24] = (32000).to_bytes(4, "big") * 2  # IHDR's width and height
    key_file.write_bytes(bytes(data))
    with pytest.raises(vmap.Error, match="is 32000x32000"):
        m.key_images[0].image
    assert m.key_images[1].gray.shape == (height, width)
    # The whole folder replaced, as vmap builds a map into it: even key images of the same size are not this Map's.
    copy.rename(tmp_path / "old_map")
    shutil.copytree(cli_dir, copy)
    with pytest.raises(vmap.Error, match="was replaced or removed since vmap.read_map read it"):
        m.key_images[1].gray
    with pytest.raises(vmap.Error, match="was replaced or removed"):
        vmap.Localizer(m)
    assert vmap.read_map(copy).key_images[1].gray.shape == (height, width)
    # Removed, and another map copied there: the new folder may take the old one's inode, not its map.json's time.
    m = vmap.read_map(copy)
    shutil.rmtree(copy)
    shutil.copytree(maps[1], copy)
    with pytest.raises(vmap.Error, match="was replaced or removed"):
        m.key_images[1].gray


def test_read_map_gives_the_map_json_as_numpy(maps):
    cli_dir, _, _ = maps
    record = map_json(cli_dir)
    m = vmap.read_map(cli_dir)
    assert [k.frame_index for k in m.key_images] == [k["frame_index"] for k in record["key_images"]]
    assert [k.timestamp for k in m.key_images] == pytest.approx([k["timestamp"] for k in record["key_images"]])
    width, height = record["input"]["frame_size"]
    image = m.key_images[0].image
    assert image.shape == (height, width, 3) and image.dtype == np.uint8
    assert m.key_images[0].gray.shape == (height, width)
    assert len(m.links) == len(record["links"]) > 0
    for link, entry in zip(m.links, record["links"]):
        assert (link.verified, link.tentative, link.below_tau) == (entry["verified"], entry["tentative"],
                                                                   entry["below_tau"])
        assert link.similarity == pytest.approx(entry["similarity"])
        assert link.F.shape == (3, 3)
        np.testing.assert_allclose(link.F.ravel(), np.array(entry["F"], dtype=float).ravel(), rtol=1e-12)
        assert link.correspondences.shape == (entry["tentative"], 4)
        assert int(link.inliers.sum()) == entry["verified"]
        # lab_floor has intrinsics: every link has its relative pose.
        assert link.R.shape == (3, 3) and link.t.shape == (3,)
        assert link.translation_known == entry["translation_known"]
        assert link.translation_sigma_deg == pytest.approx(entry["translation_sigma_deg"])
        assert link.translation_rival_cost_gap == pytest.approx(entry["translation_rival_cost_gap"])
        np.testing.assert_allclose(link.R @ link.R.T, np.eye(3), atol=1e-9)
    assert m.quality == record["quality"]
    assert m.camera is not None and m.camera == record["input"]["camera"]
    assert m.options == record["options"]
    assert m.options["source"]["first"] == 0 and m.options["source"]["stride"] == 2
    # Its folder is kept absolute: key images are still found after a change of the working directory.
    assert pathlib.Path(m.directory).is_absolute()
    # Indexed into at once, the dict outlives the map's JSON it came from (it once pointed at a freed one).
    assert m.input["fps"] == record["input"]["fps"]
    assert vmap.read_map(cli_dir).input["frame_size"] == record["input"]["frame_size"]


def key_image_file(directory, index):
    return pathlib.Path(directory) / map_json(directory)["key_images"][index]["image"]


def test_match_equals_vmap_match(maps, tmp_path):
    cli_dir, _, _ = maps
    m = vmap.read_map(cli_dir)
    out = tmp_path / "match.json"
    run_cli("match", key_image_file(cli_dir, 0), key_image_file(cli_dir, 1), "--json", out)
    cli = json.loads(out.read_text())
    # Grey images straight from the decoder, as `vmap match` reads its files.
    result = vmap.match(m.key_images[0].gray, m.key_images[1].gray, matcher="orb")
    assert (result.num_tentative, result.num_verified, result.verified) == (cli["num_tentative"],
                                                                            cli["num_verified"], cli["verified"])
    assert result.similarity == cli["similarity"]
    np.testing.assert_array_equal(result.F, np.array(cli["F"]))
    expected = np.array([[k["x0"], k["y0"], k["x1"], k["y1"]] for k in cli["matches"]], dtype=np.float32)
    np.testing.assert_array_equal(result.matches, expected)
    np.testing.assert_array_equal(result.inliers, np.array([k["inlier"] for k in cli["matches"]]))
    # ORB scores no match: null in the JSON, NaN here (a 0 would read as the worst score).
    assert all(k["score"] is None for k in cli["matches"])
    assert np.isnan(result.scores).all()


def test_match_takes_the_cli_options(maps, tmp_path):
    cli_dir, _, _ = maps
    m = vmap.read_map(cli_dir)
    out = tmp_path / "match.json"
    run_cli("match", key_image_file(cli_dir, 0), key_image_file(cli_dir, 2), "--json", out, "--threshold", "1.5",
            "--seed", "7")
    cli = json.loads(out.read_text())
    result = vmap.Matcher(threshold=1.5, seed=7).match(m.key_images[0].gray, m.key_images[2].gray)
    assert (result.num_tentative, result.num_verified) == (cli["num_tentative"], cli["num_verified"])
    # A BGR image is matched in grey.
    bgr = vmap.match(m.key_images[0].image, m.key_images[2].image)
    assert bgr.num_tentative > 0 and bgr.F.shape == (3, 3)


def test_a_deep_matcher_runs_from_the_module_as_from_the_cli(maps, tmp_path):
    """The module loads the LibTorch plugin from beside itself (it raised 'cannot open shared object file')."""
    cli_dir, _, _ = maps
    weights = SHARED / "weights" / "xfeat" / "xfeat_folded.pt"
    if not weights.is_file():
        pytest.skip(f"{weights} not found")
    m = vmap.read_map(cli_dir)
    out = tmp_path / "match.json"
    run_cli("match", key_image_file(cli_dir, 0), key_image_file(cli_dir, 1), "--json", out, "--matcher", "xfeat",
            "--weights", weights)
    cli = json.loads(out.read_text())
    result = vmap.match(m.key_images[0].image, m.key_images[1].image, matcher="xfeat", weights=str(weights))
    assert result.num_verified > 20
    assert (result.num_tentative, result.num_verified) == (cli["num_tentative"], cli["num_verified"])


def csv_rows(path):
    import csv
    with open(path) as f:
        return list(csv.DictReader(f))


def assert_same_localization(results, rows):
    assert len(results) == len(rows) > 0
    for result, row in zip(results, rows):
        assert result.status == row["status"]
        assert (result.key, result.next_key) == (int(row["key"]), int(row["next_key"]))
        assert (result.verified, result.next_verified) == (int(row["verified"]), int(row["next_verified"]))
        for name in ("similarity", "next_similarity", "heading_px", "heading_deg", "progress"):
            value = getattr(result, name)
            assert (value is None) == (row[name] == ""), name
            if value is not None:
                assert value == pytest.approx(float(row[name]), rel=1e-5, abs=1e-6), name


def test_localize_equals_vmap_localize(maps, tmp_path):
    cli_dir, _, _ = maps
    csv_file = tmp_path / "run.csv"
    run_cli("localize", cli_dir, VIDEO, "--first=1", "--last=58", "--stride=3", "--csv", csv_file, "--no-cache")
    results = vmap.localize(vmap.read_map(cli_dir), str(VIDEO), first=1, last=58, stride=3, no_cache=True)
    assert_same_localization(results, csv_rows(csv_file))
    tracked = [r for r in results if r.status != "lost"]
    assert tracked and all(r.F.shape == (3, 3) for r in tracked if r.next_key >= 0)


def test_localize_on_a_map_with_experiences_says_which_view_each_comparison_used(maps, tmp_path):
    import shutil
    cli_dir, _, _ = maps
    experienced = tmp_path / "experienced"
    shutil.copytree(cli_dir, experienced)
    # The stretch's odd frames, added as experience 1: frames queried from it verify best against their own view.
    run_cli("build", VIDEO, "--add-experience-to", experienced, "--first=1", "--last=59", "--stride=2")
    csv_file = tmp_path / "run.csv"
    run_cli("localize", experienced, VIDEO, "--first=1", "--last=58", "--stride=3", "--csv", csv_file, "--no-cache")
    rows = csv_rows(csv_file)
    results = vmap.localize(vmap.read_map(experienced), str(VIDEO), first=1, last=58, stride=3, no_cache=True)
    assert_same_localization(results, rows)
    for result, row in zip(results, rows):
        for name in ("experience", "next_experience"):
            value = getattr(result, name)
            assert (value is None) == (row[name] == ""), name
            if value is not None:
                assert value == int(row[name]), name
    assert any(r.experience == 1 or r.next_experience == 1 for r in results), "no comparison used a view"


def test_localizer_frame_by_frame_equals_vmap_localize(maps, tmp_path):
    cli_dir, _, _ = maps
    m = vmap.read_map(cli_dir)
    csv_file = tmp_path / "run.csv"
    # The map's own key images as the query, an image folder for the CLI and numpy frames for the module.
    run_cli("localize", cli_dir, cli_dir / "keys", "--csv", csv_file, "--no-cache", "--candidates", "3")
    localizer = vmap.Localizer(m, no_cache=True, candidates=3)
    results = [localizer.localize(key.gray) for key in m.key_images]
    assert_same_localization(results, csv_rows(csv_file))
    assert results[0].status == "relocalized" and results[0].key == 0


def test_threads_sharing_a_localizer_take_turns(tmp_path):
    """Two Python threads localizing frames on one Localizer: each call returns, none deadlocks (they did, in the
    localizer's speculative comparisons, on this map of three corridor frames that verify little). In a child
    process, so that a deadlock fails the test instead of hanging it."""
    needs_shared()
    frames = tmp_path / "frames"
    frames.mkdir()
    for i in (0, 5, 10):
        (frames / f"{i:07d}.jpg").symlink_to(SHARED / "data" / "corridor_conditions" / "teach" / f"{i:07d}.jpg")
    run_cli("build", frames, "-o", tmp_path / "map")
    script = ("import threading, vmap\n"
              f"m = vmap.read_map({str(tmp_path / 'map')!r})\n"
              "localizer = vmap.Localizer(m)\n"
              "images = [key.gray for key in m.key_images]\n"
              "done = []\n"
              "def work(t):\n"
              "    for j in range(30):\n"
              "        done.append(localizer.localize(images[(t + j) % len(images)]).status)\n"
              "    localizer.reset()\n"
              "threads = [threading.Thread(target=work, args=(t,)) for t in range(2)]\n"
              "[t.start() for t in threads]\n"
              "[t.join() for t in threads]\n"
              "print(len(done), sum(s != 'lost' for s in done))\n")
    child = subprocess.run([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True, env=os.environ,
                           timeout=60)
    assert child.returncode == 0
    calls, placed = map(int, child.stdout.split())
    assert calls == 60 and placed > 0  # every call returned a result, and some placed their frame


def test_results_have_the_csv_columns(maps, tmp_path):
    cli_dir, _, _ = maps
    m = vmap.read_map(cli_dir)
    result = vmap.Localizer(m, no_cache=True).localize(m.key_images[1].image)
    csv_file = tmp_path / "one.csv"
    run_cli("localize", cli_dir, key_image_file(cli_dir, 1), "--csv", csv_file, "--no-cache")
    columns = csv_file.read_text().splitlines()[0].split(",")
    # The CSV spreads F, R and t over columns F00..F22, R00..R22, tx, ty, tz.
    folded = {c[0] if c[0] in "FR" and c[1:].isdigit() else ("t" if c in ("tx", "ty", "tz") else c)
              for c in columns}
    assert folded <= set(vars(result)), folded - set(vars(result))


def test_unknown_keywords_list_the_valid_ones():
    with pytest.raises(TypeError, match="tau") as error:
        vmap.build_map("nowhere.mp4", "nowhere_map", taux=0.5)
    assert "max_iters" in str(error.value) and "stride" in str(error.value)
    assert {"first", "last", "stride", "tau", "matcher", "threshold", "no_final_key"} <= set(vmap.build_map_options())
    with pytest.raises(TypeError, match="min_verified"):
        vmap.Localizer("nowhere_map", min_verifed=3)


def test_bad_input_raises_vmap_errors(tmp_path):
    with pytest.raises(vmap.Error, match="tau"):
        vmap.build_map("nowhere.mp4", tmp_path / "out", tau=1.5)
    with pytest.raises(ValueError, match="stride"):
        vmap.build_map("nowhere.mp4", tmp_path / "out", stride="often")
    with pytest.raises(vmap.Error, match="nowhere"):
        vmap.read_map(tmp_path / "nowhere")
    image = np.zeros((480, 640), np.uint8)
    with pytest.raises(vmap.ArgumentTypeError, match=r"uint8.*\* 255"):
        vmap.match(image.astype(np.float32), image)
    with pytest.raises(TypeError, match=">> 8"):
        vmap.match(image.astype(np.uint16), image)
    with pytest.raises(vmap.Error, match="shape"):
        vmap.match(np.zeros((480, 640, 2), np.uint8), image)
    with pytest.raises(vmap.Error, match="image0"):
        vmap.match(np.zeros((4, 4), np.uint8), image)
    with pytest.raises(vmap.Error, match="matcher"):
        vmap.match(image, image, matcher="sift")
    # No features: a result, not an error.
    assert vmap.match(image, image).num_tentative == 0
    # An image that went through pickle (a multiprocessing queue) has a dtype object of its own: still uint8.
    import pickle
    unpickled = pickle.loads(pickle.dumps(image))
    assert unpickled.dtype is not image.dtype
    assert vmap.match(unpickled, image).num_tentative == 0


def test_ctrl_c_interrupts_a_build(tmp_path):
    needs_shared()
    output = tmp_path / "interrupted_map"
    script = (f"import vmap\nprint('started', flush=True)\n"
              f"try:\n    vmap.build_map({str(VIDEO)!r}, {str(output)!r}, threads=1)\n"
              "except KeyboardInterrupt:\n    print('interrupted', flush=True)\n")
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True, env=os.environ)
    assert child.stdout.readline().strip() == "started"
    time.sleep(2)  # well inside the build of 720 frames
    child.send_signal(signal.SIGINT)
    out, _ = child.communicate(timeout=120)
    assert child.returncode == 0 and out.strip() == "interrupted"
    assert not output.exists()
    assert not [p.name for p in tmp_path.iterdir()]  # no temporary left behind either


def test_the_interpreter_exits_cleanly_while_daemon_threads_are_in_vmap(maps, tmp_path):
    """Daemon threads (a GUI's, a rospy node's workers) inside vmap calls when the program ends: the calls stop at
    their next frame, and the program exits with its own status and without a word, not "Aborted" or a
    segmentation fault, and leaves no temporary output behind."""
    script = (
        "import threading, time, numpy as np, vmap\n"
        "vmap.set_log_level('quiet')\n"
        "rng = np.random.default_rng(0)\n"
        "a = rng.integers(0, 255, (240, 320), dtype=np.uint8)\n"
        "def matching():\n"
        "    m = vmap.Matcher()\n"
        "    while True:\n"
        "        m.match(a, a)\n"
        f"def building():\n    vmap.build_map({str(VIDEO)!r}, {str(tmp_path / 'map')!r})\n"
        f"def localizing():\n    vmap.localize({str(maps[0])!r}, {str(VIDEO)!r})\n"
        "for work in (matching, building, localizing):\n"
        "    threading.Thread(target=work, daemon=True).start()\n"
        "time.sleep(3)\n"
        "print('main thread ends', flush=True)\n")
    for attempt in range(2):
        done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=os.environ,
                              timeout=120)
        assert done.returncode == 0 and done.stdout.strip() == "main thread ends", done.stderr
        assert done.stderr == ""
        assert not [p.name for p in tmp_path.iterdir()]


def test_ctrl_c_interrupts_a_simulation(tmp_path):
    """Ctrl-C during vmap.simulate: KeyboardInterrupt soon (between frames, not at the end of 200 trials), no JSON,
    and the temporary teach map removed. Procedural textures: no ../shared needed."""
    route = tmp_path / "route.csv"
    route.write_text("x,y\n0,0\n3,0\n")
    output = tmp_path / "run.json"
    script = (f"import vmap\nprint('started', flush=True)\n"
              f"try:\n    vmap.simulate(route={str(route)!r}, trials=200, threads=1, camera_width=320, "
              f"camera_height=240, json={str(output)!r})\n"
              "except KeyboardInterrupt:\n    print('interrupted', flush=True)\n")
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True, env=os.environ)
    assert child.stdout.readline().strip() == "started"
    time.sleep(3)
    child.send_signal(signal.SIGINT)
    out, _ = child.communicate(timeout=60)
    assert child.returncode == 0 and out.strip() == "interrupted"
    assert [p.name for p in tmp_path.iterdir()] == ["route.csv"]
    assert not list(pathlib.Path(tempfile.gettempdir()).glob(f"*vmap-simulate-map-{child.pid}-*"))


def without_timings(value):
    """A simulation's JSON record without its wall times (seconds, milliseconds, frames per second)."""
    if isinstance(value, dict):
        timed = ("seconds", "_ms", "per_second")
        return {k: without_timings(v) for k, v in value.items() if not any(t in k for t in timed)}
    if isinstance(value, list):
        return [without_timings(v) for v in value]
    return value


def test_simulate_equals_vmap_simulate(tmp_path):
    """vmap.simulate runs the simulate pipeline as `vmap simulate` does: the same teach run, map and trials.
    Procedural textures: no ../shared needed."""
    if not os.access(CLI, os.X_OK):
        pytest.skip(f"the vmap CLI {CLI} is not built")
    route = tmp_path / "route.csv"
    route.write_text("x,y\n0,0\n3,0\n")
    small = {"route": str(route), "trials": 1, "threads": 1, "camera_width": 320, "camera_height": 240,
             "lateral_offset": 0.3}
    module = vmap.simulate(**small, map=str(tmp_path / "module_map"))
    run_cli("simulate", "--route", route, "--trials", 1, "--threads", 1, "--camera-width", 320, "--camera-height",
            240, "--lateral-offset", 0.3, "--json", tmp_path / "cli.json")
    cli = json.loads((tmp_path / "cli.json").read_text())
    assert without_timings(module) == without_timings(cli)
    assert module["summary"]["trials"] == 1 and len(module["trials"][0]["samples"]["x"]) > 10
    assert (tmp_path / "module_map" / "map.json").is_file()  # map=... keeps the teach run's map
    with pytest.raises(vmap.Error, match="trials"):
        vmap.simulate(trials=0)
