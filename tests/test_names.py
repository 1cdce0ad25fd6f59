"""ComponentName: one parse, one text, ISO 230-1 symbols, order."""

from __future__ import annotations

import pytest

from esp.core.names import ComponentName, all_component_names


@pytest.mark.parametrize(
    ("text", "kind", "axis", "about", "iso"),
    [
        ("X.linear", "linear", "X", None, "EXX"),
        ("X.straightness.Y", "straightness", "X", "Y", "EYX"),
        ("Y.angular.Z", "angular", "Y", "Z", "ECY"),
        ("Z.angular.X", "angular", "Z", "X", "EAZ"),
        ("Z.mechanical.Y", "mechanical", "Z", "Y", "EBZ"),
        ("squareness.XY", "squareness", None, "XY", "EC0Y"),
        ("squareness.ZX", "squareness", None, "XZ", "EB0Z"),
        ("squareness.YZ", "squareness", None, "YZ", "EA0Z"),
    ],
)
def test_parse_text_and_iso(text, kind, axis, about, iso):
    name = ComponentName.parse(text)
    assert (name.kind, name.axis, name.about, name.iso) == (kind, axis, about, iso)
    canonical = text if kind != "squareness" else f"squareness.{about}"
    assert str(name) == canonical
    assert ComponentName.parse(str(name)) == name


@pytest.mark.parametrize(
    "text", ["X", "X.linear.Y", "X.straightness.X", "W.linear", "squareness.XX", "X.angle.Y", ""]
)
def test_bad_names_are_refused(text):
    with pytest.raises(ValueError):
        ComponentName.parse(text)


def test_equal_to_and_hashed_like_its_text():
    name = ComponentName("angular", "X", "Z")
    assert name == "X.angular.Z" and "X.angular.Z" == name  # noqa: SIM300 (both orders)
    assert {name: 1}["X.angular.Z"] == 1 and {"X.angular.Z": 1}[name] == 1
    assert f"{name:<14}|" == "X.angular.Z   |"


def test_order_and_the_21_components():
    names = all_component_names(mechanical=False)
    assert len(names) == 21
    assert [str(n) for n in names[:6]] == [
        "X.linear",
        "X.straightness.Y",
        "X.straightness.Z",
        "X.angular.X",
        "X.angular.Y",
        "X.angular.Z",
    ]
    assert [str(n) for n in names[-3:]] == ["squareness.XY", "squareness.XZ", "squareness.YZ"]
    assert sorted(reversed(names)) == list(names)
    assert len(all_component_names()) == 30
    assert ComponentName.parse("X.mechanical.Y").profile_kind == "angular"
    assert ComponentName.parse("squareness.XY").unit == "um/m"
    assert ComponentName.parse("Y.straightness.X").unit == "um"


def test_iso_sign_of_squareness_follows_the_right_hand_rule():
    """esp's S is positive when the included angle is below 90°; ISO 230-1's E{t}0{b}
    turns the later letter b right-handed about the third axis t: a positive EC0Y turns +Y
    towards -X (angle above 90°), a positive EB0Z turns +Z towards +X (below 90°), a
    positive EA0Z turns +Z towards -Y (above 90°)."""
    signs = {p: ComponentName.parse(f"squareness.{p}").iso_sign for p in ("XY", "XZ", "YZ")}
    assert signs == {"XY": -1, "XZ": 1, "YZ": -1}
    assert ComponentName.parse("X.angular.Z").iso_sign == 1
