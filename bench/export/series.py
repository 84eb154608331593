"""A refinement sequence as one dataset for ParaView: a ParaView collection (``.pvd``) of the
levels' VTU files, or an XDMF temporal collection of the levels' grids, the level number as
the time value. The meshes differ from level to level, which both formats allow."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path


def write_pvd(target: Path, levels: list[tuple[int, Path]]) -> Path:
    """``target``.pvd listing each (level, file), files relative to the collection."""
    root = ET.Element("VTKFile", type="Collection", version="0.1")
    collection = ET.SubElement(root, "Collection")
    for level, file in levels:
        ET.SubElement(collection, "DataSet", timestep=str(level), group="", part="0",
                      file=file.relative_to(target.parent).as_posix())
    ET.ElementTree(root).write(target, xml_declaration=True, encoding="utf-8")
    return target


def write_xdmf_collection(target: Path, levels: list[tuple[int, Path]]) -> Path:
    """``target``.xdmf holding each level's grid (as meshio wrote it) with a Time element; the
    heavy data stays in the levels' HDF5 files, referenced relative to the collection."""
    root = ET.Element("Xdmf", Version="3.0")
    domain = ET.SubElement(root, "Domain")
    collection = ET.SubElement(domain, "Grid", Name="levels", GridType="Collection",
                               CollectionType="Temporal")
    for level, file in levels:
        grid = ET.parse(file).getroot().find("Domain/Grid")
        grid.set("Name", f"level-{level}")
        grid.insert(0, ET.Element("Time", Value=str(level)))
        folder = file.parent.relative_to(target.parent).as_posix()
        for item in grid.iter("DataItem"):
            if item.get("Format") == "HDF" and item.text:
                item.text = f"{folder}/{item.text.strip()}"
        collection.append(grid)
    ET.ElementTree(root).write(target, xml_declaration=True, encoding="utf-8")
    return target
