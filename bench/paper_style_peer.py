#!/usr/bin/python3
"""The paper's method written the way a research prototype would be: a straightforward, single-threaded
Python/OpenCV implementation of Algorithm 1 (Garcia-Pintos et al., Eng 2023), the peer vmap is measured against.

Same settings as `vmap build --exhaustive`: ORB with OpenCV's defaults (500 features), brute-force Hamming
matching with cross-check, cv2.findFundamentalMat(USAC_MAGSAC, 0.5, 0.999, 100000), S = inliers / tentative
matches, at least 8 tentative matches and 8 inliers; the previous frame becomes the key image when S < tau, the
frame itself (broken link) when the very next frame fails, the last frame is the final key image; key images
written as PNG with OpenCV's default settings. Frames are read as vmap reads them (grey straight from the
decoder for image files, BGR -> grey for video), so the key images are the same as vmap's.

Needs Debian's python3-opencv and python3-numpy (apt-get install python3-opencv python3-numpy); run it with
/usr/bin/python3.

  paper_style_peer.py INPUT [--tau 0.5] [-o KEY_IMAGE_DIR] [--json RESULT.json]

INPUT: a video file, a folder of images, a TUM RGB-D folder (rgb.txt) or a KITTI odometry folder (image_0/).
Prints the number of frames, the key images, Q and the time.
"""

import argparse
import json
import os
import re
import sys
import time

import cv2
import numpy as np


def natural_key(name):
    return [int(part) if part.isdigit() else part for part in re.split(r"(\d+)", name)]


def frames(path):
    """Yields (grey image, function returning the colour image) in order."""
    if os.path.isfile(path):
        capture = cv2.VideoCapture(path)
        while True:
            ok, bgr = capture.read()
            if not ok:
                return
            yield cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY), (lambda image=bgr: image)
    if os.path.isfile(os.path.join(path, "rgb.txt")):  # TUM RGB-D
        names = []
        with open(os.path.join(path, "rgb.txt")) as listing:
            for line in listing:
                if line.strip() and not line.startswith("#"):
                    names.append(os.path.join(path, line.split()[1]))
    else:
        folder = path
        for sub in ("image_0", "images", "rgb"):
            if os.path.isdir(os.path.join(path, sub)):
                folder = os.path.join(path, sub)
                break
        extensions = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".pgm", ".ppm")
        names = sorted((os.path.join(folder, f) for f in os.listdir(folder) if f.lower().endswith(extensions)),
                       key=lambda f: natural_key(os.path.basename(f)))
    for name in names:
        grey = cv2.imread(name, cv2.IMREAD_GRAYSCALE)
        if grey is None:
            continue
        yield grey, (lambda name=name: cv2.imread(name, cv2.IMREAD_COLOR))


class Peer:
    def __init__(self):
        self.orb = cv2.ORB_create()
        self.bf = cv2.BFMatcher(cv2.NORM_HAMMING, crossCheck=True)

    def features(self, grey):
        return self.orb.detectAndCompute(grey, None)

    def compare(self, key, frame):
        """S(key, frame): (matched, S)."""
        (kp0, des0), (kp1, des1) = key, frame
        if des0 is None or des1 is None:
            return False, 0.0
        matches = self.bf.match(des0, des1)
        if len(matches) < 8:
            return False, 0.0
        pts0 = np.float32([kp0[m.queryIdx].pt for m in matches])
        pts1 = np.float32([kp1[m.trainIdx].pt for m in matches])
        F, mask = cv2.findFundamentalMat(pts0, pts1, cv2.USAC_MAGSAC, 0.5, 0.999, 100000)
        if F is None or mask is None:
            return False, 0.0
        inliers = int(mask.sum())
        if inliers < 8:
            return False, 0.0
        return True, inliers / len(matches)


def build(path, tau, key_dir):
    peer = Peer()
    if key_dir:
        os.makedirs(key_dir, exist_ok=True)

    def write_key(index, color):
        if key_dir:
            cv2.imwrite(os.path.join(key_dir, "%06d.png" % index), color())

    keys, links = [], []
    key = previous = None  # (index, features, colour)
    previous_s = 0.0
    n = 0
    for index, (grey, color) in enumerate(frames(path)):
        n += 1
        frame = (index, peer.features(grey), color)
        if key is None:
            keys.append(index)
            write_key(index, color)
            key = frame
            continue
        while True:
            matched, s = peer.compare(key[1], frame[1])
            if matched and s >= tau:
                previous, previous_s = frame, s
                break
            if previous is None:  # the very next frame fails: it becomes a key image, the link is broken
                keys.append(index)
                write_key(index, color)
                links.append(s)
                key = frame
                break
            keys.append(previous[0])
            write_key(previous[0], previous[2])
            links.append(previous_s)
            key, previous = previous, None
    if previous is not None:  # the final key image
        keys.append(previous[0])
        write_key(previous[0], previous[2])
        links.append(previous_s)
    mean_s = sum(links) / len(links) if links else 0.0
    quality = 0.5 * ((1 - len(keys) / n) + mean_s) if n else 0.0
    return {"num_frames": n, "key_frames": keys, "link_similarities": links, "quality": quality}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("input")
    parser.add_argument("--tau", type=float, default=0.5)
    parser.add_argument("-o", "--output", help="folder for the key images (PNG)")
    parser.add_argument("--json", help="write the result here")
    args = parser.parse_args()
    cv2.setNumThreads(1)  # single-threaded, as a plain script is; OpenCV's threads only cost CPU in ORB
    start = time.perf_counter()
    result = build(args.input, args.tau, args.output)
    result["seconds"] = time.perf_counter() - start
    if args.json:
        with open(args.json, "w") as out:
            json.dump(result, out)
    print("frames %d, key images %d, Q %.4f, %.2f s" % (result["num_frames"], len(result["key_frames"]),
                                                        result["quality"], result["seconds"]))
    print("key frames", " ".join(map(str, result["key_frames"])))
    return 0


if __name__ == "__main__":
    sys.exit(main())
