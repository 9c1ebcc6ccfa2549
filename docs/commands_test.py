#!/usr/bin/python3
"""Runs every command block of the README and of docs/*.md (```sh) on small inputs, so that a changed default or
a renamed flag cannot break what a newcomer copies: a block fails when any of its commands fails.

Each block runs with bash (`set -e -o pipefail`: loops, `&&` and heredocs as written) in a sandbox of its own,
laid out as the repository is (`../shared` beside the working folder), with:
- `vmap`, `build/vmap` and `/work/main/build/vmap` running the binary under test through a wrapper that gives
  the commands small inputs: the placeholders the docs use (INPUT, MAP_DIR, IMAGE0, ...) become fixture files,
  fixture files (teach.mp4, repeat.mp4, a.png, teach.bag, ...) are made where a command names them, a map a
  command reads that the block does not build is built first, `--last` keeps sweeps and the sequences of
  ../shared short (30 frames; 6 with a deep matcher), and live inputs (cameras, streams) become a short video;
- `/tmp/...` inside the sandbox;
- the commands that install, build or measure (scripts/install-deps.sh, scripts/build.sh, scripts/identity_run.sh,
  ctest, cmake, ninja, bench/, build/bench/, the test binaries) and ROS 1's tools (roscore, roslaunch: its launch
  file must exist, rosservice, rostopic) checked, not run: the script or program must exist (a build target by
  name), so a renamed one still fails the block;
- what needs the network (`vmap weights --download`, `--import` of an official file, LoFTR's official
  checkpoints) checked as far as it goes: the flags exist, the command asks for the missing weights;
- the weights cache ($VMAP_WEIGHTS_DIR) inside the sandbox.

usage: commands_test.py [--vmap build/vmap] [--shared ../shared] [--build build] [FILE.md ...]
Exit status 0 when every block passed, 1 otherwise, 77 (skipped) without ../shared.
"""
import argparse
import glob
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))

# Placeholders a doc uses for the reader's own files, per doc (whole words), and everywhere.
SUBSTITUTIONS = {
    "*": {"INPUT": "video.mp4", "TEACH": "teach.mp4", "REPEAT": "repeat.mp4", "REPEAT_WINTER": "repeat.mp4",
          "REPEAT_SPRING": "repeat.mp4", "QUERY": "repeat.mp4", "MAP_DIR": "map", "MAP": "map",
          "IMAGE0": "a.png", "IMAGE1": "b.png"},
    "docs/eval.md": {"my_map": "kitti07_map", "poses.txt": "../shared/data/kitti07/poses.txt"},
    "docs/match.md": {"K": "0"},
    "docs/matchers.md": {"FILE": "../shared/weights/xfeat/xfeat_folded.pt",
                         "xfeat.pt": "../shared/weights/xfeat/xfeat_folded.pt"},
    "docs/report.md": {"video.mp4": "teach.mp4"},  # enough key images for its --link 3
}

# The wrapper that stands for `vmap`: small inputs for the binary under test (see the module's docstring).
WRAPPER = r'''#!/usr/bin/python3
import os, re, subprocess, sys
VMAP, FIXTURES = os.environ["DOC_VMAP"], os.environ["DOC_FIXTURES"]
SHORT, DEEP_SHORT = "30", "6"
LIVE = ("/dev/video", "udp://", "rtp://", "rtsp://", "rtsps://", "tcp://", "http://", "https://", "srt://")
MAP_READERS = {"info", "localize", "route", "eval", "report", "draw"}

def fixture(name):
    """A fixture file named as the command names it, made here when it is not."""
    path = os.path.join(FIXTURES, name)
    if name and not os.path.exists(name) and os.path.exists(path):
        os.symlink(path, name)

def ensure_map(name):
    """A map the block did not build: built from the fixtures (kitti07's frames where the name says so)."""
    if os.path.exists(name) or name.endswith(".json"):
        return
    source = "../shared/data/kitti07" if "kitti07" in name else "teach.mp4"
    fixture("teach.mp4")
    subprocess.run([VMAP, "build", source, "-o", name, "-q", "--last", SHORT], check=True)

def value_flags(command):
    """The flags of `vmap COMMAND` that take a value, from its --help."""
    text = subprocess.run([VMAP, command, "--help"], capture_output=True, text=True).stdout
    flags = set()
    for line in text.splitlines():
        match = re.match(r"\s+(-[^\s{]+)\s+([A-Z]+|\[)", line)
        if match:
            flags.update(match.group(1).split(","))
    return flags

args = sys.argv[1:]
command = next((a for a in args if not a.startswith("-")), "")
takes_value = value_flags(command) if command else set()
positional, skip = [], False
for a in args[args.index(command) + 1:] if command else []:
    if skip:
        skip = False
    elif a.startswith("-"):
        skip = a in takes_value and "=" not in a
    else:
        positional.append(a)
for i, a in enumerate(args):
    if a.startswith(LIVE):
        args[i] = "repeat.mp4"  # a short video stands for the camera or the stream
    if "/" not in args[i] and not args[i].startswith("-"):
        fixture(args[i])
if command == "weights" and ("--download" in args or "--import" in args):
    # The official weights files are not here (no network): the flags must exist.
    help_text = subprocess.run([VMAP, "weights", "--help"], capture_output=True, text=True).stdout
    sys.exit(0 if all(a in help_text for a in args if a.startswith("--")) else 1)
if command in MAP_READERS and positional:
    ensure_map(positional[0])
if "--add-experience-to" in args:
    ensure_map(args[args.index("--add-experience-to") + 1])
if command in ("build", "sweep", "localize") and not any(a.startswith("--last") for a in args):
    deep = any(m in args for m in ("xfeat", "aliked", "loftr"))
    inputs = positional[1:] if command == "localize" else positional[:1]
    shared = os.path.abspath("../shared") + "/"  # as given: a fixture that links into ../shared is short already
    if deep or command == "sweep" or any(os.path.abspath(p).startswith(shared) for p in inputs):
        args += ["--last", DEEP_SHORT if deep else SHORT]
if "--loftr-model" in args and args[args.index("--loftr-model") + 1] in ("outdoor", "indoor"):
    # The official LoFTR checkpoints are not shipped (no network here): the command must get as far as asking
    # for them.
    done = subprocess.run([VMAP] + args, capture_output=True, text=True)
    sys.stdout.write(done.stdout), sys.stderr.write(done.stderr)
    sys.exit(0 if done.returncode == 0 or "no weights for --loftr-model" in done.stderr else done.returncode)
os.execv(VMAP, [VMAP] + args)
'''

# Scripts of the repository the blocks run as they are (quick); the others are checked, not run.
RUN_AS_IS = {"scripts/identity_options.sh"}

# A program the block names that is checked, not run: it exists, then the command passes.
STUB = "#!/bin/sh\nexit 0\n"


def blocks(files):
    for path in files:
        text = open(path, encoding="utf-8").read()
        for match in re.finditer(r"^```sh\n(.*?)^```", text, re.S | re.M):
            yield os.path.relpath(path, ROOT), text.count("\n", 0, match.start()) + 1, match.group(1)


def make_fixtures(folder, vmap, shared):
    """teach.mp4 (lab_floor), video.mp4 and repeat.mp4 (its first 45 frames), a.png, b.png and snapshot.png (three
    of its frames), teach.bag and repeat.bag (30 of its frames as sensor_msgs/Image on /cam/image_raw)."""
    video = os.path.join(shared, "data", "lab_floor", "lab_floor.mp4")
    os.symlink(video, os.path.join(folder, "teach.mp4"))
    ffmpeg = ["ffmpeg", "-v", "error", "-y", "-i", video]
    subprocess.run(ffmpeg + ["-frames:v", "45", "-c:v", "mpeg4", "-q:v", "2", os.path.join(folder, "short.mp4")],
                   check=True)
    for name in ("video.mp4", "repeat.mp4"):
        os.symlink("short.mp4", os.path.join(folder, name))
    for name, frame in (("a.png", 0), ("b.png", 8), ("snapshot.png", 20)):
        subprocess.run(ffmpeg + ["-vf", f"select=eq(n\\,{frame})", "-frames:v", "1", os.path.join(folder, name)],
                       check=True)
    raw = subprocess.run(ffmpeg + ["-frames:v", "30", "-f", "rawvideo", "-pix_fmt", "gray", "-"], check=True,
                         capture_output=True).stdout
    import genpy
    import rosbag
    from sensor_msgs.msg import Image
    width, height = 640, 480
    with rosbag.Bag(os.path.join(folder, "teach.bag"), "w") as bag:
        for i in range(len(raw) // (width * height)):
            stamp = genpy.Time.from_sec(1.0 + i / 30.0)
            image = Image(height=height, width=width, encoding="mono8", step=width,
                          data=raw[i * width * height:(i + 1) * width * height])
            image.header.stamp, image.header.frame_id = stamp, "camera"
            bag.write("/cam/image_raw", image, stamp)
    os.symlink("teach.bag", os.path.join(folder, "repeat.bag"))


def make_sandbox(root, vmap, shared, build, fixtures, block):
    """root/work (the working folder, as the repository's root), root/shared, root/tmp, root/bin/vmap."""
    work = os.path.join(root, "work")
    os.makedirs(os.path.join(work, "build"))
    os.makedirs(os.path.join(root, "tmp"))
    os.symlink(shared, os.path.join(root, "shared"))
    os.makedirs(os.path.join(root, "bin"))
    for wrapper in (os.path.join(root, "bin", "vmap"), os.path.join(work, "build", "vmap")):
        with open(wrapper, "w") as f:
            f.write(WRAPPER)
        os.chmod(wrapper, 0o755)
    # Checked, not run: a stub where the repository (scripts/, bench/, examples/) or the build has the program.
    for folder in ("scripts", "bench"):
        for path in glob.glob(os.path.join(ROOT, folder, "*")):
            stub = os.path.join(work, folder, os.path.basename(path))
            os.makedirs(os.path.dirname(stub), exist_ok=True)
            if os.path.relpath(path, ROOT) in RUN_AS_IS:
                shutil.copy(path, stub)
                continue
            with open(stub, "w") as f:
                f.write("#!/usr/bin/python3\n" if path.endswith(".py") else STUB)
            os.chmod(stub, 0o755)
    # The programs the build makes (bench/, the test binaries), as its build system lists them: built or not yet.
    listed = subprocess.run(["ninja", "-C", build, "-t", "targets", "all"], capture_output=True, text=True).stdout
    for line in listed.splitlines():
        path, _, rule = line.partition(": ")
        if "EXECUTABLE_LINKER" not in rule or "[" in path or os.path.isabs(path) or path == "vmap":
            continue
        stub = os.path.join(work, "build", path)
        os.makedirs(os.path.dirname(stub), exist_ok=True)
        with open(stub, "w") as f:
            f.write(STUB)
        os.chmod(stub, 0o755)
    # Other files of the build the block names (build/ros/devel/setup.sh): there, empty (sourced or run, they do
    # nothing).
    for path in set(re.findall(r"(?<![\w/])build/([\w./-]+)", block)):
        stub = os.path.join(work, "build", path)
        if os.path.isfile(os.path.join(build, path)) and not os.path.exists(stub):
            os.makedirs(os.path.dirname(stub), exist_ok=True)
            open(stub, "w").close()
            os.chmod(stub, 0o755)
    shutil.copytree(os.path.join(ROOT, "examples"), os.path.join(work, "examples"))
    return work


# Stand-ins for the tools that build and test: they check their targets exist.
PREAMBLE = r'''
set -e -o pipefail
ctest() { :; }
cmake() { :; }
# ROS 1 (docs/ros.md): the node's launch files must exist; the master and its tools are not run.
roscore() { :; }
rosservice() { :; }
rostopic() { :; }
rosparam() { :; }
rosnode() { :; }
rosrun() { :; }
roslaunch() {
  [[ "$1" == vmap_ros && -f "$DOC_ROOT/ros/launch/$2" ]] || { echo "no launch file $2 in package $1" >&2; return 1; }
}
ninja() {
  for target in "$@"; do
    case "$target" in -*|build) continue;; esac
    ninja_targets=${ninja_targets:-$(command ninja -C "$DOC_BUILD" -t targets all 2>/dev/null | cut -d: -f1)}
    grep -qx "$target" <<<"$ninja_targets" || { echo "no build target $target" >&2; return 1; }
  done
}
'''


def prepare(text, file, sandbox):
    for scope in ("*", file):
        for word, value in SUBSTITUTIONS.get(scope, {}).items():
            text = re.sub(rf"(?<![\w./-]){re.escape(word)}(?![\w-])", value, text)
    text = text.replace("/work/main/build/vmap", "build/vmap")
    text = re.sub(r"(?<![\w.])/tmp/", sandbox + "/tmp/", text)
    return text


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--vmap", default=os.path.join(ROOT, "build", "vmap"))
    parser.add_argument("--shared", default=os.environ.get("VMAP_SHARED_DIR", os.path.join(ROOT, "..", "shared")))
    parser.add_argument("--build", default=os.path.join(ROOT, "build"))
    parser.add_argument("files", nargs="*")
    options = parser.parse_args()
    shared, vmap, build = (os.path.abspath(p) for p in (options.shared, options.vmap, options.build))
    if not os.path.isfile(os.path.join(shared, "data", "lab_floor", "lab_floor.mp4")):
        print(f"skipped: {shared} has no data/lab_floor (../shared is not there)")
        return 77
    files = options.files or [os.path.join(ROOT, "README.md")] + sorted(glob.glob(os.path.join(ROOT, "docs", "*.md")))
    failures = 0
    with tempfile.TemporaryDirectory(prefix="vmap_doc_commands_") as temp:
        fixtures = os.path.join(temp, "fixtures")
        os.makedirs(fixtures)
        make_fixtures(fixtures, vmap, shared)
        for number, (file, line, block) in enumerate(blocks(files)):
            sandbox = os.path.join(temp, f"block{number}")
            work = make_sandbox(sandbox, vmap, shared, build, fixtures, block)
            script = PREAMBLE + prepare(block, file, sandbox)
            env = dict(os.environ, DOC_VMAP=vmap, DOC_FIXTURES=fixtures, DOC_BUILD=build, DOC_ROOT=ROOT,
                       VMAP_WEIGHTS_DIR=os.path.join(sandbox, "weights"),
                       PATH=os.path.join(sandbox, "bin") + os.pathsep + os.environ["PATH"])
            start = time.monotonic()
            done = subprocess.run(["bash", "-c", script], cwd=work, env=env, capture_output=True, text=True,
                                  timeout=900)
            seconds = time.monotonic() - start
            if done.returncode == 0:
                print(f"ok      {file}:{line} ({seconds:.1f} s)")
            else:
                failures += 1
                print(f"FAILED  {file}:{line} (status {done.returncode}, {seconds:.1f} s)\n{block}"
                      f"--- output:\n{done.stdout[-3000:]}{done.stderr[-3000:]}")
            shutil.rmtree(sandbox, ignore_errors=True)
    print(f"{failures} of the blocks failed" if failures else "every block passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
