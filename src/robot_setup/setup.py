from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(**generate_distutils_setup(packages=["robot_setup", "robot_setup.templates"], package_dir={"": "src"}))
