"""Write ``holed_block.msh``: a 2 x 1 block with a circular hole, meshed by Gmsh, its boundary
curves in the physical groups that ``examples/holed_block.toml`` names:

    python examples/meshes/make_holed_block.py [OUT.msh] [MESH_SIZE]

(``pip install gmsh``). The committed ``holed_block.msh`` came from this script with the
defaults; a test regenerates it when gmsh is importable and runs the scene on both.
"""

import sys
from pathlib import Path

import gmsh


def make_holed_block(out: Path, size: float = 0.25) -> Path:
    gmsh.initialize(["-noenv"])
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("holed-block")
        occ = gmsh.model.occ
        block = occ.addRectangle(-1.0, 0.0, 0.0, 2.0, 1.0)
        hole = occ.addDisk(0.0, 0.55, 0.0, 0.2, 0.2)
        occ.cut([(2, block)], [(2, hole)])
        occ.synchronize()
        curves = {"top": [], "bottom": [], "sides": [], "hole": []}
        for _, tag in gmsh.model.getEntities(1):
            x0, y0, _, x1, y1, _ = gmsh.model.getBoundingBox(1, tag)
            if abs(y0 - 1.0) < 1e-6 and abs(y1 - 1.0) < 1e-6:
                curves["top"].append(tag)
            elif abs(y0) < 1e-6 and abs(y1) < 1e-6:
                curves["bottom"].append(tag)
            elif abs(x1 - x0) < 1e-6:
                curves["sides"].append(tag)
            else:
                curves["hole"].append(tag)
        for name, tags in curves.items():
            gmsh.model.addPhysicalGroup(1, tags, name=name)
        surfaces = [tag for _, tag in gmsh.model.getEntities(2)]
        gmsh.model.addPhysicalGroup(2, surfaces, name="body")
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.model.mesh.generate(2)
        gmsh.write(str(out))
    finally:
        gmsh.finalize()
    return out


if __name__ == "__main__":
    here = Path(__file__).parent
    target = Path(sys.argv[1]) if len(sys.argv) > 1 else here / "holed_block.msh"
    print(make_holed_block(target, float(sys.argv[2]) if len(sys.argv) > 2 else 0.25))
