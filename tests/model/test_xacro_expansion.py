"""dynid's own xacro expansion against the format's reference implementation (the ``xacro`` package, which evaluates
with Python's ``eval`` and so is run here on the test's own files only), and the files it must refuse."""

import shutil
import xml.dom.minidom
from pathlib import Path

import pytest
import xacro

from dynid.exceptions import ConfigError
from dynid.model.xacro_expansion import MAX_DEPTH, MAX_ELEMENTS, expand_xacro_text

FEATURES = Path(__file__).parents[1] / "data" / "xacro"
"""A description using every construct of the format dynid expands: namespaced and plain includes, YAML with units,
lazy, quoted, default, removed and scoped properties, macros with forwarded defaults, single and multiple blocks,
``xacro:call``, conditionals, ``xacro:element``/``xacro:attribute``, ``$(arg)``, ``$(eval)`` and ``$$`` escapes."""


def _canonical(text: str) -> list[str]:
    """Elements, attributes and non-blank text in document order (comments and indentation left out)."""
    out: list[str] = []

    def walk(node, depth):
        for c in node.childNodes:
            if c.nodeType == c.ELEMENT_NODE:
                out.append("  " * depth + c.tagName + " " + " ".join(f"{k}={v!r}" for k, v in sorted(c.attributes.items())))
                walk(c, depth + 1)
            elif c.nodeType == c.TEXT_NODE and c.data.strip():
                out.append("  " * depth + "#" + c.data.strip())

    walk(xml.dom.minidom.parseString(text).documentElement, 0)
    return out


def _reference(path: Path, arguments=None) -> list[str]:
    return _canonical(xacro.process_file(str(path), mappings=dict(arguments or {})).toprettyxml())


@pytest.mark.parametrize("arguments", [{}, {"prefix": "r_", "with_tool": "false", "scale": "3"}])
def test_the_expansion_is_the_reference_implementations(tmp_path, arguments):
    for f in FEATURES.iterdir():
        shutil.copy(f, tmp_path / f.name)
    path = tmp_path / "arm.urdf.xacro"
    text, read = expand_xacro_text(path, arguments)
    ours = _canonical(text)
    assert ours == _reference(path, arguments)
    assert len(ours) > 20 and not any("xacro:" in line for line in ours)
    assert sorted(Path(f).name for f in read) == ["arm.urdf.xacro", "inc.xacro", "ns.xacro", "p.yaml"]


BROKEN = {
    "undefined property": ('<link name="${nowhere}"/>', r"name 'nowhere' is not defined"),
    "unknown macro": ("<xacro:nothing/>", r"no macro named 'nothing'"),
    "missing parameter": ('<xacro:macro name="m" params="a b"><x a="${a}"/></xacro:macro><xacro:m a="1"/>',
                          r"the macro 'm' needs the parameters b"),
    "unknown parameter": ('<xacro:macro name="m" params="a"/><xacro:m a="1" c="2"/>', r"the macro 'm' has no parameter 'c'"),
    "unused block": ('<xacro:macro name="m" params=""/><xacro:m><x/></xacro:m>', r"the macro 'm' got a block <x> it has no parameter for"),
    "circular property": ('<xacro:property name="a" value="${b}"/><xacro:property name="b" value="${a}"/>'
                          '<x v="${a}"/>', r"circular property definition"),
    "undefined argument": ('<x v="$(arg nothing)"/>', r"the argument 'nothing' is not defined"),
    "not a condition": ('<xacro:if value="maybe"><x/></xacro:if>', r"the condition 'maybe' is 'maybe', not a boolean"),
    "missing include": ('<xacro:include filename="nothing.xacro"/>', r"cannot read .*nothing.xacro"),
    "unclosed expression": ('<x v="${1 + 2"/>', r"cannot read"),
    "not XML": ('<link name="x">', r".*arm.urdf.xacro is not XML \(mismatched tag: line 1"),
    "property without a name": ('<xacro:property value="1"/>', r"<xacro:property> needs the attribute 'name'"),
    "property name": ('<xacro:property name="1x" value="1"/>', r"the property name '1x' is not a name"),
    "value and default": ('<xacro:property name="p" value="1" default="2"/>',
                          r"the property 'p' has more than one of value, default and remove"),
    "macro named call": ('<xacro:macro name="call" params=""/>', r"'call' cannot name a macro"),
    "call without a macro": ("<xacro:call/>", r"<xacro:call> needs the attribute 'macro'"),
    "call of no macro": ('<xacro:call macro="nosuch"/>', r"no macro named 'nosuch'"),
    "missing block": ('<xacro:macro name="m" params="*b"><xacro:insert_block name="b"/></xacro:macro><xacro:m/>',
                      r"the macro 'm' needs a block for '\*b'"),
    "no such block": ('<xacro:macro name="m" params="*b"><xacro:insert_block name="c"/></xacro:macro><xacro:m><x/></xacro:m>',
                      r"<xacro:insert_block name='c'>: no such block"),
    "forwarding nothing": ('<xacro:macro name="m" params="a:=^"><link name="${a}"/></xacro:macro><xacro:m/>',
                           r"the macro 'm' forwards 'a', which is not defined"),
    "element without a name": ('<xacro:element xacro:name=""/>', r"<xacro:element> has an empty name"),
    "attribute without a name": ('<link name="l"><xacro:attribute name="" value="1"/></link>',
                                 r"<xacro:attribute> has an empty name"),
    "unknown substitution": ('<link name="$(nosuch thing)"/>', r"cannot read the substitution \$\(nosuch thing\)"),
    "unset environment variable": ('<link name="$(env DYNID_TEST_UNSET_VARIABLE)"/>',
                                   r"the environment variable DYNID_TEST_UNSET_VARIABLE is not set"),
}


def _refused(folder: Path, body: str, message: str) -> Path:
    """A description of ``body`` that dynid refuses in one line matching ``message``."""
    path = folder / "arm.urdf.xacro"
    path.write_text(f'<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">{body}</robot>')
    with pytest.raises(ConfigError, match=r"arm.urdf.xacro: xacro cannot expand it: " + message) as info:
        expand_xacro_text(path)
    assert "\n" not in str(info.value)
    return path


@pytest.mark.parametrize("case", BROKEN.values(), ids=BROKEN.keys())
def test_what_the_reference_refuses_is_refused_in_one_line(tmp_path, case):
    path = _refused(tmp_path, *case)
    with pytest.raises(Exception):  # noqa: B017  # the reference refuses it too, in its own words
        xacro.process_file(str(path))


def test_find_resolves_a_package_beside_the_file_or_on_the_package_path(tmp_path, monkeypatch):
    """``$(find pkg)`` without ROS: the package folder the file sits in (a cloned description package), one on
    ROS_PACKAGE_PATH, else one line naming the package."""
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)
    for package in ("arm_description", "other/tool_description"):
        folder = tmp_path / package
        (folder / "urdf").mkdir(parents=True)
        (folder / "package.xml").write_text(f"<package><name>{Path(package).name}</name></package>")
    (tmp_path / "other" / "tool_description" / "urdf" / "tool.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="tool"/></robot>')
    path = tmp_path / "arm_description" / "urdf" / "arm.urdf.xacro"
    path.write_text('<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                    '<link name="base" mesh="$(find arm_description)/m.stl"/>'
                    '<xacro:include filename="$(find tool_description)/urdf/tool.xacro"/></robot>')
    with pytest.raises(ConfigError, match=r"\$\(find tool_description\) names a ROS package dynid cannot find"):
        expand_xacro_text(path)
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "other"))
    lines = _canonical(expand_xacro_text(path)[0])
    assert lines == [f"link mesh={str(tmp_path / 'arm_description' / 'm.stl')!r} name='base'", "link name='tool'"]


HOSTILE = {
    "self-calling macro": ('<xacro:macro name="m" params=""><xacro:m/></xacro:macro><xacro:m/>',
                           f"macro calls or includes nested deeper than {MAX_DEPTH}"),
    "doubling macros": ("".join(f'<xacro:macro name="m{i}" params=""><xacro:m{i - 1}/><xacro:m{i - 1}/></xacro:macro>'
                                for i in range(1, 40)).replace("<xacro:m0/><xacro:m0/>", "<a/><a/>")
                        + "<xacro:m39/>", f"the expansion makes more than {MAX_ELEMENTS:,} elements"),
    "self-including file": ('<xacro:include filename="arm.urdf.xacro"/>',
                            f"macro calls or includes nested deeper than {MAX_DEPTH}"),
}


@pytest.mark.parametrize("case", HOSTILE.values(), ids=HOSTILE.keys())
def test_an_expansion_without_end_is_refused(tmp_path, case):
    _refused(tmp_path, *case)
