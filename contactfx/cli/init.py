"""``contactfx init SCENE [scene options] [numerics] --out DIR``: a built-in scene as a problem
file with its mesh beside it (:mod:`contactfx.scenes.export`)."""

from __future__ import annotations

import shlex
from pathlib import Path

from contactfx.cli.run import fields_of, scene_numerics, scene_parser
from contactfx.scenes import get_scene

__all__ = ["cmd_init"]


def cmd_init(argv: list[str], comm) -> int:
    if not argv or argv[0].startswith("-"):
        if argv and argv[0] in ("-h", "--help"):
            if comm.rank == 0:
                print("usage: contactfx init SCENE [options] --out DIR; see `contactfx list`")
            return 0
        raise ValueError(
            "missing scene name: contactfx init SCENE --out DIR (see `contactfx list`)"
        )
    scene_cls = get_scene(argv[0])
    if comm.rank != 0 and ("-h" in argv or "--help" in argv):
        return 0
    parser = scene_parser(scene_cls, command="init")
    ns = vars(parser.parse_args(argv[1:]))
    if ns["out"] is None:
        raise ValueError("contactfx init: give the output folder with --out DIR")
    scene = scene_cls(scene_cls.Params(**fields_of(scene_cls.Params, ns)))
    numerics = scene_numerics(scene_cls, ns)
    command = "contactfx init " + shlex.join(argv)
    from contactfx.scenes.export import write_problem

    msh, toml = write_problem(scene, numerics, Path(ns["out"]), command, comm)
    if comm.rank == 0 and not ns["quiet"]:
        print(f"contactfx: wrote {toml} and its mesh {msh.name}")
        print(f"  solve it with: contactfx solve {toml}")
    return 0
