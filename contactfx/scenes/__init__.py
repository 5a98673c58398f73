"""The scene registry: named contact problems with their parameters and references."""

from __future__ import annotations

from contactfx.numerics import Numerics
from contactfx.scenes.bar import Bar1D, BarImpact
from contactfx.scenes.base import Scene
from contactfx.scenes.crack import CrackInclined, CrackSet, CrackSneddon, ProppedFracture
from contactfx.scenes.disc_drop import DiscDrop
from contactfx.scenes.flat_punch import FlatPunch2D, FlatPunch3D
from contactfx.scenes.hertz import Hertz2D, Hertz3D, HertzAxi
from contactfx.scenes.hertz_impact import HertzImpact
from contactfx.scenes.ironing import ShallowIroning, ShallowIroning3D
from contactfx.scenes.joint import JointColumn
from contactfx.scenes.penny import FaultBlock, PennyCrack, PennyShear
from contactfx.scenes.sliding_block import SlidingBlock
from contactfx.scenes.sliding_stop import SlidingStop, SlidingStopPlinth
from contactfx.scenes.sphere_slide import SphereSlide
from contactfx.scenes.two_bars import TwoBars
from contactfx.scenes.two_body import HertzCylinders, HertzSpheres, PatchTest
from contactfx.scenes.two_body_2d import CattaneoCylinders, PunchFoundation, SlidingContact
from contactfx.scenes.westergaard import Westergaard

__all__ = ["SCENES", "get_scene", "Scene", "Numerics"]

SCENES: dict[str, type[Scene]] = {
    cls.name: cls
    for cls in (
        Hertz2D,
        Hertz3D,
        HertzAxi,
        Westergaard,
        FlatPunch2D,
        FlatPunch3D,
        SlidingBlock,
        SlidingStop,
        SlidingStopPlinth,
        TwoBars,
        Bar1D,
        BarImpact,
        DiscDrop,
        HertzImpact,
        CrackSneddon,
        CrackInclined,
        ProppedFracture,
        CrackSet,
        PennyCrack,
        PennyShear,
        FaultBlock,
        JointColumn,
        PatchTest,
        HertzCylinders,
        HertzSpheres,
        PunchFoundation,
        SlidingContact,
        CattaneoCylinders,
        ShallowIroning,
        ShallowIroning3D,
        SphereSlide,
    )
}


def get_scene(name: str) -> type[Scene]:
    try:
        return SCENES[name]
    except KeyError:
        known = ", ".join(SCENES)
        raise ValueError(f"unknown scene '{name}' (known: {known})") from None
