"""The logs: what a dataset's table says of a log (:mod:`.dataset_specs`), CSV tables, ROS bags and MCAP read into a
:class:`~dynid.io.logs.datasets.Recording`, their columns detected and repaired, and the excitation trajectories
written for the robot. Nothing here imports the configs (:mod:`dynid.io.config`), which decode into it."""
