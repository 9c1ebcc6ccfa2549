"""Every argument is converted with its type checked: a wrong type is a TypeError (vmap.ArgumentTypeError, also a
vmap.Error), a bad value a vmap.Error, never a crash; an image's size is checked before any copy. Options are
keywords named as their fields, with the CLI's flag names as aliases."""
import os
import re
import subprocess
import sys

import numpy as np
import pytest

import vmap
from conftest import VIDEO, needs_shared


def run_isolated(code):
    """Runs `code` in a fresh interpreter (a crash there fails the test instead of ending pytest)."""
    done = subprocess.run([sys.executable, "-c", "import vmap\nvmap.set_log_level('quiet')\n" + code],
                          capture_output=True, text=True, timeout=300, env=os.environ)
    assert done.returncode >= 0, f"killed by signal {-done.returncode}: {done.stderr}"
    return done


def localize_in_isolation(cli_dir, arguments):
    """Localizes the map's first key image with `arguments` (Python source) in a fresh interpreter: what it raised, or
    'accepted'."""
    done = run_isolated(f"""
m = vmap.read_map({str(cli_dir)!r})
localizer = vmap.Localizer(m, no_cache=True)
try:
    localizer.localize(m.key_images[0].gray, {arguments})
except (TypeError, vmap.Error) as e:
    print(type(e).__name__, e)
else:
    print('accepted')
""")
    assert done.returncode == 0, done.stderr
    return done.stdout


@pytest.mark.parametrize("timestamp", ["'now'", "[1.0]", "object()", "10**400", "b'1'", "float('nan')", "True",
                                       "-5.0"])
def test_a_bad_timestamp_is_an_exception(maps, timestamp):
    said = localize_in_isolation(maps[0], f"timestamp={timestamp}")
    assert "accepted" not in said and "timestamp" in said, said


def test_a_good_timestamp_is_recorded(maps):
    cli_dir, _, _ = maps
    m = vmap.read_map(cli_dir)
    localizer = vmap.Localizer(m, no_cache=True)
    assert localizer.localize(m.key_images[0].gray, timestamp=12.5).timestamp == 12.5
    assert localizer.localize(m.key_images[1].gray, timestamp=np.float32(13)).timestamp == 13.0


@pytest.mark.parametrize("odometry", ["(1.0, 2.0)", "'abc'", "(1, 2, float('nan'))", "object()", "[1, 2, 'x']",
                                      "(1, 2, 10**400)", "b'abc'"])
def test_a_bad_odometry_pose_is_an_exception(maps, odometry):
    said = localize_in_isolation(maps[0], f"timestamp=1.0, odometry={odometry}")
    assert "accepted" not in said and "odometry" in said, said


def test_the_odometry_paces_the_belief_with_the_teach_odometry(maps, tmp_path):
    """The robot's pose with each frame, against the teach run's odometry: the belief moves by the distance driven
    (three steps a key image's worth), whatever the frames' times say."""
    cli_dir, _, _ = maps
    m = vmap.read_map(cli_dir)
    times = [k.timestamp for k in m.key_images]
    assert len(times) >= 3 and all(t is not None for t in times)
    teach = tmp_path / "teach_odometry.csv"
    # The teach run at 1 m/s along x: a key image's worth is the mean time between key images, in metres.
    teach.write_text("timestamp,x,y,yaw\n" + "".join(f"{t:.6f},{t:.6f},0,0\n" for t in
                                                     [times[0] - 1.0] + times + [times[-1] + 1.0]))
    per_key = (times[-1] - times[0]) / (len(times) - 1)
    taught = vmap.Localizer(m, no_cache=True, teach_odometry=str(teach))
    untaught = vmap.Localizer(m, no_cache=True)
    for localizer in (taught, untaught):
        localizer.localize(m.key_images[0].gray, timestamp=times[0], odometry=(0.0, 0.0, 0.0))
    # Two key images' worth driven in a tenth of a key image's time.
    second = dict(image=m.key_images[1].gray, timestamp=times[0] + 0.1 * per_key, odometry=(2.0 * per_key, 0.0, 0.0))
    assert taught.localize(**second).motion_steps == 6
    assert untaught.localize(**second).motion_steps == 1


def test_huge_broadcast_images_are_refused_before_any_copy():
    image = np.zeros((480, 640), np.uint8)
    for shape in [(100000, 100000), (80000, 80000), (2**31, 8)]:
        done = run_isolated(f"""
import numpy as np, resource
resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))  # a copy of the image would not fit
try:
    vmap.match(np.broadcast_to(np.uint8(7), {shape}), np.zeros((480, 640), np.uint8))
except vmap.Error as e:
    print('refused:', e)
""")
        assert done.returncode == 0, done.stderr
        assert "refused:" in done.stdout and "image0" in done.stdout, done.stdout
    with pytest.raises(vmap.ArgumentTypeError, match="image1"):
        vmap.match(image, [[0, 1], [2, 3]])
    with pytest.raises(TypeError, match="image0"):
        vmap.match(object(), image)


@pytest.mark.parametrize("value", ["'often'", "1.5", "True", "[2]", "b'2'", "object()", "10**400"])
def test_option_values_are_type_checked(value, tmp_path):
    done = run_isolated(f"""
try:
    vmap.build_map('nowhere.mp4', {str(tmp_path / 'out')!r}, stride={value})
except vmap.Error as e:
    print(type(e).__name__, isinstance(e, TypeError), e)
""")
    assert done.returncode == 0, done.stderr
    assert "stride" in done.stdout, done.stdout
    if value != "10**400":  # a value out of range is a vmap.Error; a value of the wrong type also a TypeError
        assert "ArgumentTypeError True" in done.stdout, done.stdout


def test_wrong_types_are_type_errors_and_vmap_errors(tmp_path):
    # Named by the function called: match(), not the Matcher it makes for the pair.
    with pytest.raises(TypeError, match=r"^match\(\): threshold takes a number, not str"):
        vmap.match(np.zeros((8, 8), np.uint8), np.zeros((8, 8), np.uint8), threshold="1")
    with pytest.raises(vmap.Error, match="matcher 'ORB' is unknown; matchers are named in lower case: use orb"):
        vmap.match(np.zeros((8, 8), np.uint8), np.zeros((8, 8), np.uint8), matcher="ORB")
    with pytest.raises(vmap.Error, match="no_cache takes True or False"):
        vmap.Localizer(tmp_path, no_cache=1)
    with pytest.raises(TypeError, match="verifier takes a str"):
        vmap.Matcher(verifier=3)
    with pytest.raises(vmap.ArgumentTypeError, match="map"):
        vmap.Localizer(42)
    with pytest.raises(vmap.Error, match="NUL"):
        vmap.Localizer("a\0b")
    with pytest.raises(vmap.ArgumentTypeError, match="trials"):
        vmap.simulate(trials="many")
    with pytest.raises(vmap.Error, match="lateral_offset"):
        vmap.simulate(lateral_offset=float("nan"))
    with pytest.raises(vmap.Error, match="missing.csv"):
        vmap.simulate(route=str(tmp_path / "missing.csv"), json=str(tmp_path / "run.json"))
    assert not (tmp_path / "run.json").exists()
    assert issubclass(vmap.ArgumentTypeError, TypeError) and issubclass(vmap.ArgumentTypeError, vmap.Error)


def test_keywords_are_field_names_with_the_flags_as_aliases():
    keywords = set(vmap.build_map_options())
    # Fields' names (as their record nests them) and the CLI's flag names for the same fields.
    assert {"verifier_max_iterations", "max_iters", "orb_num_features", "orb_features", "pose_threshold",
            "tau", "first", "extraction_threads", "threads", "final_key", "no_final_key", "search"} <= keywords
    # A field is given once, whichever name it is given by.
    with pytest.raises(TypeError, match="one option twice"):
        vmap.Matcher(threshold=1.0, verifier_threshold=2.0)
    a = vmap.Matcher(verifier_threshold=1.5, verifier_seed=7)
    b = vmap.Matcher(threshold=1.5, seed=7)
    image = np.zeros((64, 64), np.uint8)
    assert a.name == b.name == "orb" and a.match(image, image).num_tentative == b.match(image, image).num_tentative


def documented_keywords(doc):
    """The keywords a docstring's "Keywords" part lists: 'name: type = default (or alias=)' lines."""
    line_of_keyword = re.compile(r"^    (\w+): (int|float|bool|str)\b.* = \S+(?: \((?:or (\w+)=|the opposite of (\w+))\))?$")
    names = set()
    for line in doc.split("Keywords (None keeps the default):")[1].splitlines():
        match = line_of_keyword.match(line)
        if match:
            names.update(name for name in (match.group(1), match.group(3), match.group(4)) if name)
    return names


def test_help_lists_every_keyword_under_the_headings_of_the_commands_help():
    doc = vmap.build_map.__doc__
    documented = documented_keywords(doc)
    accepted = set(vmap.build_map_options())
    # Every keyword taken is documented, by its field's name or its flag's.
    assert documented == accepted
    # The headings of `vmap build --help`, in its order; a negated flag by the keyword its help describes.
    headings = ("Input:", "Matcher and features", "Verifier: the fundamental matrix:", "Key images:")
    positions = [doc.index("\n" + h) for h in headings]
    assert positions == sorted(positions)
    assert ("    no_final_key: bool = False (the opposite of final_key)\n"
            "        Do not make the last frame a key image") in doc
    assert "    verifier_max_iterations: int in [1, 10000000] = 100000 (or max_iters=)" in doc
    # The localizer's: what a user sets first, the rules after, and a default the help describes is None's.
    doc = vmap.localize.__doc__
    assert doc.index("\nRoute and odometry:") < doc.index("\nAcceptance: when a frame is at a key image:") < \
        doc.index("\nRules across seasons and lighting") < doc.index("\nRun: threads, caches and seeds:")
    assert ("    from: int -1 or [0, 2147483647] = None\n"
            "        Follow the route from this key image (default: the first)") in doc
    assert "csv" not in documented_keywords(doc)  # the CLI's outputs are not the function's
    assert documented_keywords(vmap.Localizer.__doc__) <= documented_keywords(doc)
    assert "matcher: str = 'orb'" in vmap.Matcher.__doc__ and "route: str = " in vmap.simulate.__doc__


def test_errors_name_options_by_keyword(tmp_path):
    with pytest.raises(vmap.Error, match=r"^verifier_threshold -1 px is outside \(0, 100\] \(default 0\.5 px\)$"):
        vmap.Matcher(threshold=-1)
    with pytest.raises(vmap.Error, match="^tau 1.5 is outside"):
        vmap.build_map("nowhere.mp4", tmp_path / "out", tau=1.5)


def test_min_verified_belongs_to_the_counts_rule(maps):
    cli_dir, _, _ = maps
    with pytest.raises(vmap.Error, match="min_verified belongs to acceptance counts"):
        vmap.Localizer(cli_dir, min_verified=20)
    localizer = vmap.Localizer(cli_dir, acceptance="counts", min_verified=20, no_cache=True)
    assert localizer.localize(vmap.read_map(cli_dir).key_images[0].gray).status != "lost"


def test_the_quickstart_example_runs(tmp_path):
    needs_shared()
    example = os.path.join(os.path.dirname(__file__), "..", "..", "examples", "python_quickstart.py")
    env = dict(os.environ, PYTHONPATH=os.path.dirname(vmap.__file__))  # the module under test, from any folder
    done = subprocess.run([sys.executable, example, str(VIDEO)], capture_output=True, text=True, timeout=600,
                          env=env, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "links:" in done.stdout and "match:" in done.stdout and "frame " in done.stdout, done.stdout


def test_objects_made_by_new_alone_are_refused_not_followed():
    """Class.__new__(Class) makes an object whose __init__ never ran: using one crashed the interpreter (Matcher,
    Link) or read garbage (KeyImage). Each is now a TypeError; the map's views cannot be made that way at all."""
    done = run_isolated("""
import numpy as np
grey = np.zeros((64, 64), np.uint8)
uses = {
    "Matcher.match": lambda: vmap.Matcher.__new__(vmap.Matcher).match(grey, grey),
    "Matcher.name": lambda: vmap.Matcher.__new__(vmap.Matcher).name,
    "Matcher.match on another type": lambda: vmap.Matcher.match(42, grey, grey),
    "Localizer.localize": lambda: vmap.Localizer.__new__(vmap.Localizer).localize(grey),
    "Localizer.reset": lambda: vmap.Localizer.__new__(vmap.Localizer).reset(),
    "KeyImage": lambda: vmap.KeyImage.__new__(vmap.KeyImage).image,
    "Link": lambda: vmap.Link.__new__(vmap.Link).F,
    "Map": lambda: vmap.Map.__new__(vmap.Map).key_images,
}
for name, use in uses.items():
    try:
        use()
        print(name, "accepted")
    except TypeError as error:
        print(name, "TypeError", str(error).splitlines()[0])
""")
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert len(lines) == 8, done.stdout
    for line in lines:
        assert " TypeError " in line, line
    assert "a vmap.Matcher made with vmap.Matcher(...) was expected" in lines[0]
    assert "vmap.KeyImage objects come from vmap.read_map" in lines[5]


def test_module_functions_check_their_text_arguments():
    with pytest.raises(vmap.ArgumentTypeError, match=r"read_map\(\): directory takes a str"):
        vmap.read_map(None)
    with pytest.raises(vmap.Error, match="NUL"):
        vmap.read_map("a\0b")
    with pytest.raises(vmap.ArgumentTypeError, match=r"set_log_level\(\): level takes a str"):
        vmap.set_log_level(None)


def test_build_map_into_no_folder_is_refused_before_any_work(tmp_path, monkeypatch):
    # The CLI's default folder beside the input (lab_floor_map) would replace a map the call never named.
    needs_shared()
    monkeypatch.chdir(tmp_path)
    with pytest.raises(vmap.Error, match="output_dir '' names no folder"):
        vmap.build_map(str(VIDEO), "", first=0, last=9)
    assert list(tmp_path.iterdir()) == []


def test_two_builds_into_one_folder_never_return_the_other_ones_map(tmp_path):
    # Each returns its own map or says the folder was another build's too; the one read back once was the other's.
    needs_shared()
    import threading

    def key_images(output, first):
        m = vmap.build_map(str(VIDEO), str(output), first=first, last=first + 9)
        return [k.source_index for k in m.key_images]

    alone = {first: key_images(tmp_path / f"alone_{first}", first) for first in (0, 100)}
    assert alone[0] != alone[100]
    for round_ in range(3):
        output = tmp_path / f"shared_{round_}"
        outcomes = {}

        def build(first):
            try:
                outcomes[first] = key_images(output, first)
            except vmap.Error as e:
                outcomes[first] = str(e)

        threads = [threading.Thread(target=build, args=(first,)) for first in (0, 100)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        for first, outcome in outcomes.items():
            if isinstance(outcome, str):
                assert "give each build a folder of its own" in outcome, outcome
            else:
                assert outcome == alone[first], (first, outcome)


def test_initialize_runtime_checks_its_arguments_as_every_function_does():
    done = run_isolated("""
for kwargs in ({'opencv_threads': 2**40}, {'keep_freed_memory': 0}, {'quiet_ffmpeg': 'yes'}, {'opencv_threads': 1.5}):
    try:
        vmap.initialize_runtime(**kwargs)
        print('accepted', kwargs)
    except vmap.Error as e:
        print(type(e).__name__, kwargs)
vmap.initialize_runtime(opencv_threads=None, keep_freed_memory=None, quiet_ffmpeg=None)
print('defaults')
""")
    assert done.returncode == 0, done.stderr
    assert "accepted" not in done.stdout, done.stdout
    assert done.stdout.count("ArgumentTypeError") == 3, done.stdout  # the wrong types; 2**40 is out of range
    assert done.stdout.endswith("defaults\n"), done.stdout


def test_a_route_end_or_start_that_is_no_key_image_names_its_keyword(maps):
    m = vmap.read_map(maps[0])
    last = len(m.key_images) - 1
    for keyword in ("from", "to", "start_key"):
        with pytest.raises(vmap.Error, match=rf"{keyword} 99 is no key image: the map has key images 0 to {last}"):
            vmap.Localizer(m, no_cache=True, **{keyword: 99})


def test_a_runs_weights_and_device_are_checked_by_their_keywords(maps, tmp_path):
    # The run's own settings of the map's matcher, named as Python names them.
    cli_dir, _, _ = maps
    with pytest.raises(vmap.Error, match=r"weights '.*nowhere\.pt' is not a file"):
        vmap.Localizer(cli_dir, weights=str(tmp_path / "nowhere.pt"))
    with pytest.raises(vmap.Error, match="device 'gpu' is not a device"):
        vmap.Localizer(cli_dir, device="gpu")
