"""The choices of ``simkit export`` (formats, CSV conventions, bag stamps): names only, so that the command-line
parser is built without importing the exporters (numpy's and scipy's start-up belong to a run that exports)."""

FORMATS = ("rosbag2", "csv", "kml")
BODY_FRAMES = ("ned-frd", "enu-rfu", "enu-flu")  # CSV: navigation and body axes
STAMPS = ("unix", "gps", "start")                # bag stamps: UTC as ROS time, GPS seconds, since the start
