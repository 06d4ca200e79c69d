"""Fitting a force/torque sensor's noise model from a recording (pure: numpy and rosbags, no ROS).

A wrench recording is read (:mod:`sensor_fit.recordings`: a ROS 1 bag topic of geometry_msgs/WrenchStamped,
or a CSV), the windows where the sensor is at rest are found (:mod:`sensor_fit.rest_windows`), and per axis
the offset, white noise and a slow AR(1) drift are fitted, with the sample rate, its jitter, gaps, the
largest one-sample jumps and the offset change across a contact (:mod:`sensor_fit.noise_model`, its results
in :mod:`sensor_fit.results`). :mod:`sensor_fit.report` prints them and writes them as a ``wrench:`` section
of a driver profile (mujoco_driver's ``config/profiles/*.yaml``). Command line: ``fit_sensor`` (or
``python -m sensor_fit``), :mod:`sensor_fit.cli`; see ``--help``.
"""
