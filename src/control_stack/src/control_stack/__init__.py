"""contact_control and jog_arm in one process; see node.py."""
