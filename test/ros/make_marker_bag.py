#!/usr/bin/env python3
"""Writes a small bag of the Visualizer's topics (a formation of three UAVs with frusta, the
worker with its covariance, plans, status text; a voxel map) for the rviz replay test.
usage: make_marker_bag.py OUT.bag"""
import math
import sys

import rosbag
import rospy
from geometry_msgs.msg import Point
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

COLORS = [(0.9, 0.1, 0.1), (0.1, 0.8, 0.1), (0.1, 0.3, 1.0)]  # Visualizer: leader, follower 1, follower 2


def marker(ns, i, typ, t, rgba):
    m = Marker()
    m.header.frame_id = "world"
    m.header.stamp = t
    m.ns, m.id, m.type, m.action = ns, i, typ, Marker.ADD
    m.pose.orientation.w = 1.0
    m.color = ColorRGBA(*rgba)
    m.lifetime = rospy.Duration(2.0)
    return m


def main():
    bag = rosbag.Bag(sys.argv[1], "w")
    worker = (3.0, 5.0, 10.0)  # in the view of config/rviz/gesture_formation.rviz
    try:
        mp = MarkerArray()
        m = marker("map", 0, Marker.CUBE_LIST, rospy.Time(0.1), (0.55, 0.55, 0.6, 0.6))
        m.scale.x = m.scale.y = m.scale.z = 0.4
        m.lifetime = rospy.Duration(0)
        for z in range(0, 60):
            for dx in (-1.5, 1.5):
                m.points.append(Point(-2.0 + dx, -1.5, z * 0.4))
                m.points.append(Point(-2.0 + dx, 1.5, z * 0.4))
        mp.markers.append(m)
        bag.write("/visualization/map", mp, rospy.Time(0.1))
        for k in range(1, 120):
            t = rospy.Time(0.1 * k)
            a = MarkerArray()
            for i, (r, g, b) in enumerate(COLORS):
                ang = math.radians(90 + 120 * i) + 0.01 * k
                p = Point(worker[0] + 9 * math.cos(ang), worker[1] + 9 * math.sin(ang), worker[2] + 2)
                s = marker("uavs", i, Marker.SPHERE, t, (r, g, b, 1.0))
                s.pose.position = p
                s.scale.x = s.scale.y = s.scale.z = 1.5
                a.markers.append(s)
                line = marker("plans", i, Marker.LINE_STRIP, t, (r, g, b, 1.0))
                line.scale.x = 0.3
                line.points = [Point(p.x + 0.2 * j * math.cos(ang + 1.6), p.y + 0.2 * j * math.sin(ang + 1.6), p.z)
                               for j in range(30)]
                a.markers.append(line)
            w = marker("worker_cov", 0, Marker.SPHERE, t, (1.0, 0.9, 0.0, 0.6))
            w.pose.position = Point(*worker)
            w.scale.x, w.scale.y, w.scale.z = 2.0, 2.0, 3.0
            a.markers.append(w)
            txt = marker("status", 0, Marker.TEXT_VIEW_FACING, t, (1.0, 1.0, 1.0, 1.0))
            txt.pose.position = Point(worker[0], worker[1], worker[2] + 6)
            txt.scale.z = 1.0
            txt.text = "gesture 2  fired: all.distance_m +1"
            a.markers.append(txt)
            bag.write("/visualization/markers", a, t)
    finally:
        bag.close()


if __name__ == "__main__":
    main()
