"""The thesis demonstrations (section 6.4), run against a live stack through its ROS interface."""
