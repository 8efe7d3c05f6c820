"""The exported model: URDF and MJCF written from a robot or a results.json (a user's own file written back), and read
back by Pinocchio and MuJoCo against dynid's model."""
