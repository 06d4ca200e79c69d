"""Named joint configurations and joint-space moves to them (pure: `poses`, `profile`; ROS: `node`)."""
