#!/usr/bin/python3
"""Write the committed test inputs under test/data/perception/ from Debian's opencv-doc images.

Run with Debian's /usr/bin/python3 (python3-opencv 4.6). Deterministic (integer-exact
OpenCV resize with INTER_AREA on fixed rectangles; PNG without timestamps).

  messi5.jpg (548x342, one footballer, full body)
    pose_det_224.png       whole image letterboxed (keep aspect, black bars top/bottom) to 224x224
    pose_crop_256.png      square crop x 65..465, y -10..390 (black outside) resized to 256x256
    pose_crop_192.png      the same square crop resized to 192x192
  basketball1.png (640x480, grey, two people)
    multipose_256.png      whole image letterboxed to 256x256
"""
import os
import sys

import cv2
import numpy as np

DATA = "/usr/share/doc/opencv-doc/examples/data"


def letterbox(img, size):
    h, w = img.shape[:2]
    s = size / max(h, w)
    nw, nh = round(w * s), round(h * s)
    r = cv2.resize(img, (nw, nh), interpolation=cv2.INTER_AREA)
    out = np.zeros((size, size, 3), np.uint8)
    y0, x0 = (size - nh) // 2, (size - nw) // 2
    out[y0:y0 + nh, x0:x0 + nw] = r
    return out


def square_crop(img, x0, y0, side):
    out = np.zeros((side, side, 3), np.uint8)
    h, w = img.shape[:2]
    sx0, sy0 = max(x0, 0), max(y0, 0)
    sx1, sy1 = min(x0 + side, w), min(y0 + side, h)
    out[sy0 - y0:sy1 - y0, sx0 - x0:sx1 - x0] = img[sy0:sy1, sx0:sx1]
    return out


def main():
    outdir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "../../test/data/perception")
    messi = cv2.imread(os.path.join(DATA, "messi5.jpg"))
    bball = cv2.imread(os.path.join(DATA, "basketball1.png"))
    if messi is None or bball is None:
        sys.exit("make_inputs: opencv-doc images missing (apt-get install opencv-doc)")
    crop = square_crop(messi, 65, -10, 400)
    imgs = {
        "pose_det_224.png": letterbox(messi, 224),
        "pose_crop_256.png": cv2.resize(crop, (256, 256), interpolation=cv2.INTER_AREA),
        "pose_crop_192.png": cv2.resize(crop, (192, 192), interpolation=cv2.INTER_AREA),
        "multipose_256.png": letterbox(bball, 256),
    }
    for name, im in imgs.items():
        cv2.imwrite(os.path.join(outdir, name), im, [cv2.IMWRITE_PNG_COMPRESSION, 9])
        print("make_inputs: wrote", name, im.shape)


if __name__ == "__main__":
    main()
