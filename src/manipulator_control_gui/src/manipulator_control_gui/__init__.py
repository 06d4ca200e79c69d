"""Qt panel for contact_control: one contact law per Cartesian axis, Apply/Stop/Tare/Reset, live status.

`config` and `form` (the form and its mapping to ConfigureForceControl) and `readout` are pure Python;
`ros_client` is the rospy side; `widget`, `plugin` and `app` are the Qt side.
"""
