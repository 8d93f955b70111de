"""Gazebo's `collide_bitmask` / `category_bitmask` as MuJoCo `contype` / `conaffinity`.

SDFormat (surface.sdf): two collisions collide when (category1 & collide2) | (category2 &
collide1) ≠ 0; both masks are 16 bits, default 0xFFFF, and an unset category is the collide
mask. Gazebo Classic's ODE (`ODEPhysics::Collide`) tests collide1 & collide2, the same rule
when no category is given. MuJoCo collides two geoms when (contype1 & conaffinity2) |
(contype2 & conaffinity1) ≠ 0: the same test with contype = category, conaffinity = collide.

An untagged geom keeps MuJoCo's contype = conaffinity = 1, which stands for Gazebo's default
0xFFFF, so the ground, untagged robots and MJCF entities need no change. A tagged geom
therefore moves its masks up one bit and uses bit 0 of conaffinity for "meets the default":

    contype = category << 1,  conaffinity = (collide << 1) | (1 if category | collide else 0)

Tagged-tagged pairs test ((cat1 & col2) | (cat2 & col1)) << 1 (no tagged contype has bit 0);
a tagged geom meets an untagged one (1, 1) iff category | collide ≠ 0, as against 0xFFFF.
"""

from __future__ import annotations

from dataclasses import dataclass

GAZEBO_DEFAULT_MASK = 0xFFFF  # SDFormat surface.sdf collide_bitmask / category_bitmask default
MASK_BITS = 0xFFFF  # SDFormat parses both masks as 16-bit unsigned integers


@dataclass(frozen=True)
class CollideBits:
    """A tagged geom's Gazebo masks and their MuJoCo encoding.

    Attributes:
        category, collide: the 16-bit Gazebo masks (category defaults to collide).
        contype, conaffinity: the MuJoCo values that reproduce Gazebo's rule.
        dropped: bits above 16 the file gave, which SDFormat does not keep (0 if none).
    """

    category: int
    collide: int
    contype: int
    conaffinity: int
    dropped: int = 0


def collide_bits(category: int | None, collide: int | None) -> CollideBits | None:
    """The MuJoCo encoding of a geom's masks, or None when neither is given.

    Args:
        category: `category_bitmask`, or None (then the collide mask).
        collide: `collide_bitmask`, or None (then Gazebo's default 0xFFFF).
    """
    if category is None and collide is None:
        return None
    raw_collide = GAZEBO_DEFAULT_MASK if collide is None else collide
    raw_category = raw_collide if category is None else category
    dropped = (raw_collide | raw_category) & ~MASK_BITS
    col, cat = raw_collide & MASK_BITS, raw_category & MASK_BITS
    meets_default = 1 if (cat | col) else 0
    return CollideBits(cat, col, cat << 1, (col << 1) | meets_default, dropped)


def gazebo_collides(first: tuple[int, int], second: tuple[int, int]) -> bool:
    """SDFormat's rule for two (category, collide) pairs: does the pair collide?"""
    return bool((first[0] & second[1]) | (second[0] & first[1]))


def describe(bits: CollideBits) -> str:
    """One report line: the masks, the MuJoCo values and the rule."""
    text = (
        f"category_bitmask=0x{bits.category:04x} collide_bitmask=0x{bits.collide:04x} → "
        f"contype={bits.contype} conaffinity={bits.conaffinity}: collides with a geom when "
        "(category & its collide) | (its category & collide) ≠ 0, with untagged geoms "
        "(Gazebo's 0xffff, MuJoCo's 1/1) when either mask is non-zero"
    )
    if bits.dropped:
        text += f"; bits 0x{bits.dropped:x} above 16 dropped (SDFormat parses 16 bits)"
    return text
