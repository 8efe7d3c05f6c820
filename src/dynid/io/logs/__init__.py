"""The logs: CSV tables, ROS bags and MCAP read into a :class:`~dynid.io.logs.datasets.Recording`, their columns
detected and repaired, and the excitation trajectories written for the robot."""
