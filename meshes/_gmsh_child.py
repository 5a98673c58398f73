"""Mesh a ``.geo`` file in a process of its own: ``python _gmsh_child.py GEO MSH SIZE_FACTOR``.

Run by :func:`contactfx.meshes.file_groups` (never imported): gmsh's parser and mesher meet the
user's geometry here, so that a geometry gmsh cannot mesh ends this process, not the run (an
open curve loop or a self-intersecting one throws inside gmsh's OpenMP region, which terminates
the process with a C++ backtrace). The mesh of the highest dimension of a physical group is
written to ``MSH`` (gmsh 4.1, binary: the node coordinates are the doubles themselves; every
entity, so that the file read back is the model meshed here). gmsh's messages go to stdout:
the caller reads its ``Error`` lines.
"""

import sys

import gmsh


def main(geo: str, msh: str, size_factor: float) -> int:
    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 1)
        gmsh.model.add("geo")
        gmsh.option.setNumber("Mesh.MeshSizeFactor", size_factor)
        gmsh.merge(geo)
        dims = [d for d, _ in gmsh.model.getPhysicalGroups()]
        if dims:
            gmsh.model.mesh.generate(max(dims))
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.Binary", 1)
        gmsh.option.setNumber("Mesh.SaveAll", 1)
        gmsh.write(msh)
    except Exception as exc:  # gmsh's Python API: its last error (also printed as "Error")
        print(f"Error   : {exc}", flush=True)
        return 1
    finally:
        gmsh.finalize()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2], float(sys.argv[3])))
