#!/usr/bin/env python3
"""Records the Visualizer's mode labels (namespace `modes`) from /visualization/markers: one line
`t id text` per label and tick (t = the marker's stamp, sim time) to the file given, until killed.
Used by test/ros/worker_lost_hold.sh. Usage: watch_modes.py OUT_FILE"""
import sys

import rospy
from visualization_msgs.msg import MarkerArray


def main():
    out = open(sys.argv[1], "w", buffering=1)

    def cb(a):
        for m in a.markers:
            if m.ns == "modes":
                out.write("%.2f %d %s\n" % (m.header.stamp.to_sec(), m.id, m.text))

    rospy.init_node("watch_modes", anonymous=True)
    rospy.Subscriber("/visualization/markers", MarkerArray, cb, queue_size=20)
    rospy.spin()


if __name__ == "__main__":
    main()
