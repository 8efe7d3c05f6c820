"""A written description says where its joint angles differ from the encoders' (the description's position offsets)."""

from importlib import resources

import pinocchio as pin

from dynid.model.description import load_robot
from dynid.model.description_files import mjcf_from_robot, urdf_from_robot

NOTE = "encoder angle (what a log and the controller hold) plus its position_offset (J2 +90°)"


def test_urdf_and_mjcf_written_from_a_dh_table_say_the_offsets(tmp_path):
    """The ER-16's DH table with J2's encoder zero a quarter turn away (``position_offset = "pi/2"``): the URDF and
    MJCF written from it say that their angles are the encoders' plus the offset (they said nothing, and a controller's
    angles given to them are a quarter turn off on J2); without the offset, nothing is said."""
    text = (resources.files("dynid.model") / "robots" / "er16.toml").read_text()
    head, first, rest = text.partition('[[joints]]\nname = "joint2"\n')
    (tmp_path / "arm.toml").write_text(head + first + 'position_offset = "pi/2"\n' + rest)
    offset = load_robot(tmp_path / "arm.toml")
    for write in (urdf_from_robot, mjcf_from_robot):
        assert NOTE in write(offset) and "position_offset" not in write(load_robot("er16"))
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(urdf_from_robot(offset))
    assert pin.buildModelFromUrdf(str(urdf)).nq == 6  # the comment keeps the file a URDF
