"""Keyboard jogging: key map (`keymap`), teleop logic (`teleop`), terminal reader (`terminal`), node (`node`).

The generated messages (`keyboard_publisher.msg`) live in the catkin devel space, not here. When this source
directory comes first on sys.path (pytest's conftest), extending `__path__` lets the devel `msg` subpackage
still be found.
"""

from pkgutil import extend_path

__path__ = extend_path(__path__, __name__)
