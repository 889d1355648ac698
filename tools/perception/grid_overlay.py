#!/usr/bin/env python3
"""Draws a labelled pixel grid over an image (or a video frame) so that person boxes can be
read off by eye in an image viewer. Used once to make test/data/perception/labels/.

usage: grid_overlay.py IMAGE|VIDEO OUT.png [--frame N] [--step PX] [--resize W H] [--zoom F]
"""
import argparse

import cv2


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("src")
    ap.add_argument("out")
    ap.add_argument("--frame", type=int, default=-1, help="frame index when src is a video")
    ap.add_argument("--step", type=int, default=20)
    ap.add_argument("--resize", type=int, nargs=2, default=None, help="resize to W H before drawing")
    ap.add_argument("--zoom", type=float, default=1.0, help="display zoom (labels stay in source px)")
    ap.add_argument("--crop", type=int, nargs=4, default=None, help="x y w h (source px) to show only")
    a = ap.parse_args()
    if a.frame >= 0:
        cap = cv2.VideoCapture(a.src)
        cap.set(cv2.CAP_PROP_POS_FRAMES, a.frame)
        ok, img = cap.read()
        assert ok, "cannot read frame"
    else:
        img = cv2.imread(a.src)
    if a.resize:
        img = cv2.resize(img, tuple(a.resize), interpolation=cv2.INTER_AREA)
    x0, y0 = 0, 0
    if a.crop:
        x0, y0, w, h = a.crop
        img = img[y0:y0 + h, x0:x0 + w]
    z = a.zoom
    img = cv2.resize(img, None, fx=z, fy=z, interpolation=cv2.INTER_NEAREST)
    hh, ww = img.shape[:2]
    for gx in range((x0 // a.step) * a.step, x0 + int(ww / z) + 1, a.step):
        px = int(round((gx - x0) * z))
        if px < 0:
            continue
        major = gx % (a.step * 5) == 0
        cv2.line(img, (px, 0), (px, hh - 1), (0, 255, 255) if major else (0, 160, 0), 1)
        if major:
            cv2.putText(img, str(gx), (px + 2, 12), cv2.FONT_HERSHEY_PLAIN, 0.9, (0, 255, 255), 1)
    for gy in range((y0 // a.step) * a.step, y0 + int(hh / z) + 1, a.step):
        py = int(round((gy - y0) * z))
        if py < 0:
            continue
        major = gy % (a.step * 5) == 0
        cv2.line(img, (0, py), (ww - 1, py), (0, 255, 255) if major else (0, 160, 0), 1)
        if major:
            cv2.putText(img, str(gy), (2, py - 2), cv2.FONT_HERSHEY_PLAIN, 0.9, (0, 255, 255), 1)
    cv2.imwrite(a.out, img)


if __name__ == "__main__":
    main()
