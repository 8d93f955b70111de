"""`collide_bitmask` / `category_bitmask`: a cube dropped on another rests on it or falls through.

Oracle: SDFormat's rule worked by hand for each row, (category1 & collide2) | (category2 &
collide1) ≠ 0, the category defaulting to the collide mask and both to 0xFFFF (the ground and
untagged cubes). A cube that meets the lower one rests with its centre at 0.15 m; one that
does not falls through it to the ground, at 0.05 m.
"""

from __future__ import annotations

import pytest
from models import block, write_urdf

from converters.gazebo.collide_bits import collide_bits, gazebo_collides
from converters.pipeline import convert
from converters.report import Outcome
from twin_cli.world import Pose, World

EDGE = 0.1  # [m] cube edge
ON_TOP, ON_GROUND = 1.5 * EDGE, 0.5 * EDGE  # [m] rest heights of the upper cube's centre
HEIGHT_TOL = 0.005  # [m] contact sinkage and settling are well under this
SETTLE_STEPS = 1000  # 1 s at 1 ms: the upper cube falls 0.15 m in 0.17 s, then settles

# (label, lower (category, collide), upper (category, collide), collide by hand); None = unset
ROWS = [
    ("both untagged", (None, None), (None, None), True),
    ("same collide bit", (None, 0x1), (None, 0x1), True),
    ("disjoint collide bits", (None, 0x1), (None, 0x2), False),
    ("one shared bit of two", (None, 0x3), (None, 0x2), True),
    ("untagged meets any non-zero mask", (None, None), (None, 0x8000), True),
    ("category of lower in collide of upper", (0x1, 0x2), (0x4, 0x1), True),
    ("category of upper in collide of lower", (0x1, 0x4), (0x4, 0x8), True),
    ("categories in neither collide", (0x1, 0x2), (0x4, 0x8), False),
    ("tagged lower meets untagged upper", (None, 0x4), (None, None), True),
]


def tagged_cube(name: str, masks: tuple[int | None, int | None]) -> str:
    """A 1 kg cube of edge EDGE with the given (category, collide) masks on its collision."""
    category, collide = masks
    contact = "".join(
        f"<{tag}>{value}</{tag}>"
        for tag, value in (("category_bitmask", category), ("collide_bitmask", collide))
        if value is not None
    )
    text = block(name=name, size=EDGE)
    if not contact:
        return text
    gazebo = (
        f'<gazebo reference="{name}"><collision><surface><contact>{contact}</contact>'
        "</surface></collision></gazebo>"
    )
    return text.replace("</robot>", gazebo + "</robot>")


def _full(masks: tuple[int | None, int | None]) -> tuple[int, int]:
    category, collide = masks
    col = 0xFFFF if collide is None else collide
    return (col if category is None else category, col)


@pytest.mark.parametrize(("label", "lower", "upper", "collides"), ROWS, ids=[r[0] for r in ROWS])
def test_dropped_cube_rests_on_the_lower_iff_gazebo_collides_them(
    tmp_path, label, lower, upper, collides
):
    assert gazebo_collides(_full(lower), _full(upper)) is collides, f"hand oracle for {label}"
    world = World()
    for name, masks, z in (("lower", lower, ON_GROUND), ("upper", upper, 0.3)):
        spec, _ = convert(write_urdf(tmp_path, tagged_cube(name, masks), f"{name}.urdf"))
        world.spawn(spec, name=name, pose=Pose(z=z))
    world.step(SETTLE_STEPS)
    upper_z = float(world.data.body("upper/upper").xpos[2])
    lower_z = float(world.data.body("lower/lower").xpos[2])
    expected = ON_TOP if collides else ON_GROUND
    assert lower_z == pytest.approx(ON_GROUND, abs=HEIGHT_TOL), f"lower cube z {lower_z} m"
    assert upper_z == pytest.approx(expected, abs=HEIGHT_TOL), f"{label}: upper z {upper_z} m"


def test_a_cube_that_collides_with_nothing_falls_through_the_ground(tmp_path):
    spec, _ = convert(write_urdf(tmp_path, tagged_cube("box", (None, 0x0))))
    world = World()
    world.spawn(spec, name="box", pose=Pose(z=ON_GROUND))
    world.step(300)
    z = float(world.data.body("box/box").xpos[2])
    assert z < -0.2, f"a collide_bitmask 0 cube stays at z {z} m; Gazebo lets it fall (0 & 0xffff)"


@pytest.mark.parametrize(
    ("masks", "contype", "conaffinity", "outcome"),
    [
        ((None, 0x1), 2, 3, Outcome.MAPPED),
        ((0x4, 0x1), 8, 3, Outcome.APPROXIMATED),  # Gazebo Classic ignores the category
        ((None, 0x0), 0, 0, Outcome.MAPPED),
        ((None, 0xFFFF), 0x1FFFE, 0x1FFFF, Outcome.MAPPED),
    ],
)
def test_masks_move_up_one_bit_and_bit_zero_meets_untagged_geoms(
    tmp_path, masks, contype, conaffinity, outcome
):
    spec, report = convert(write_urdf(tmp_path, tagged_cube("box", masks)))
    model = spec.compile()
    assert model.ngeom == 1, f"the cube has one (collision) geom, not {model.ngeom}"
    assert (int(model.geom_contype[0]), int(model.geom_conaffinity[0])) == (
        contype,
        conaffinity,
    ), f"contype/conaffinity for {masks}"
    entries = [e for e in report.entries if e.tag in ("collide_bitmask", "category_bitmask")]
    assert entries and entries[0].outcome is outcome, entries


def test_category_other_than_collide_is_reported_as_gazebo_classic_ignores_it(tmp_path):
    _, report = convert(write_urdf(tmp_path, tagged_cube("box", (0x4, 0x1))))
    entry = next(e for e in report.entries if e.tag == "collide_bitmask")
    assert entry.outcome is Outcome.APPROXIMATED and "Gazebo Classic" in entry.detail, entry


def test_bits_above_sixteen_are_dropped_and_reported():
    bits = collide_bits(None, 0x10002)
    assert bits is not None and (bits.collide, bits.dropped) == (0x2, 0x10000), bits
    assert bits.conaffinity < 2**31, f"MuJoCo's contype/conaffinity are int: {bits}"


def sdf_cube(name: str, collide: int) -> str:
    """An SDF model: a 1 kg cube of edge EDGE whose collision has `collide_bitmask`."""
    i = EDGE**2 / 6  # [kg m²] solid cube of 1 kg
    return f"""<?xml version="1.0"?>
<sdf version="1.9"><model name="{name}"><link name="{name}">
  <inertial><mass>1</mass><inertia><ixx>{i}</ixx><iyy>{i}</iyy><izz>{i}</izz></inertia></inertial>
  <collision name="c"><geometry><box><size>{EDGE} {EDGE} {EDGE}</size></box></geometry>
    <surface><contact><collide_bitmask>{collide}</collide_bitmask></contact></surface>
  </collision></link></model></sdf>"""


@pytest.mark.parametrize(("lower", "upper", "collides"), [(0x1, 0x1, True), (0x1, 0x2, False)])
def test_sdf_collision_bitmask_decides_as_in_urdf(tmp_path, lower, upper, collides):
    world = World()
    for name, mask, z in (("lower", lower, ON_GROUND), ("upper", upper, 0.3)):
        path = tmp_path / f"{name}.sdf"
        path.write_text(sdf_cube(name, mask))
        spec, _ = convert(path)
        world.spawn(spec, name=name, pose=Pose(z=z))
    world.step(SETTLE_STEPS)
    upper_z = float(world.data.body("upper/upper").xpos[2])
    expected = ON_TOP if collides else ON_GROUND
    assert upper_z == pytest.approx(expected, abs=HEIGHT_TOL), f"SDF upper cube z {upper_z} m"
