"""VTK XML unstructured grids (.vtu) of nodes, and .pvd time series, for ParaView.

Binary appended data, zlib-compressed in blocks (header_type UInt64), as VTK writes it:
each array is [number of blocks, block size, size of the last block, compressed sizes...]
followed by the compressed blocks. Nodes are written as VTK_VERTEX cells.
"""

from __future__ import annotations

import os
import zlib
from collections.abc import Mapping
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np
from numpy.typing import NDArray

from granulate.io.atomic import atomic_write

_BLOCK = 1 << 16
_VTK_TYPES = {
    np.dtype(np.float64): "Float64",
    np.dtype(np.float32): "Float32",
    np.dtype(np.int64): "Int64",
    np.dtype(np.int32): "Int32",
    np.dtype(np.uint32): "UInt32",
    np.dtype(np.uint8): "UInt8",
}


def _compressed(array: NDArray[np.generic]) -> bytes:
    raw = np.ascontiguousarray(array).astype(array.dtype.newbyteorder("<"), copy=False).tobytes()
    blocks = [raw[k : k + _BLOCK] for k in range(0, len(raw), _BLOCK)] or [b""]
    packed = [zlib.compress(block, 6) for block in blocks]
    header = np.array(
        [len(blocks), _BLOCK, len(blocks[-1]), *(len(p) for p in packed)], dtype="<u8"
    )
    return header.tobytes() + b"".join(packed)


def write_vtu(
    path: str | os.PathLike[str],
    points: NDArray[np.float64],
    point_data: Mapping[str, NDArray[np.generic]],
) -> None:
    """Write nodes and their fields as a .vtu file (atomically).

    Args:
        path: target file.
        points: (n, 3) node positions.
        point_data: name -> (n,) or (n, k) array; dtypes float64/float32/int64/int32/uint32/uint8.
    """
    n = len(points)
    arrays: list[tuple[str, str, bytes]] = []  # (section, name, payload)
    descriptors: list[str] = []
    offset = 0

    def add(section: str, name: str, values: NDArray[np.generic]) -> None:
        nonlocal offset
        values = np.asarray(values)
        if values.dtype not in _VTK_TYPES:
            values = values.astype(np.float64)
        components = "" if values.ndim == 1 else f' NumberOfComponents="{values.shape[1]}"'
        payload = _compressed(values)
        name_attr = f" Name={quoteattr(name)}" if name else ""
        descriptors.append(
            f'<DataArray type="{_VTK_TYPES[values.dtype]}"{name_attr}{components} '
            f'format="appended" offset="{offset}"/>'
        )
        arrays.append((section, name, payload))
        offset += len(payload)

    for name, values in point_data.items():
        add("point", name, values)
    point_count = len(descriptors)
    add("points", "", np.asarray(points, dtype=np.float64))
    add("cells", "connectivity", np.arange(n, dtype=np.int64))
    add("cells", "offsets", np.arange(1, n + 1, dtype=np.int64))
    add("cells", "types", np.ones(n, dtype=np.uint8))

    xml = [
        '<?xml version="1.0"?>',
        '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
        'header_type="UInt64" compressor="vtkZLibDataCompressor">',
        "<UnstructuredGrid>",
        f'<Piece NumberOfPoints="{n}" NumberOfCells="{n}">',
        "<PointData>",
        *descriptors[:point_count],
        "</PointData>",
        "<Points>",
        descriptors[point_count],
        "</Points>",
        "<Cells>",
        *descriptors[point_count + 1 :],
        "</Cells>",
        "</Piece>",
        "</UnstructuredGrid>",
        '<AppendedData encoding="raw">',
    ]
    body = "\n".join(xml).encode() + b"\n_" + b"".join(a[2] for a in arrays)
    atomic_write(path, body + b"\n</AppendedData>\n</VTKFile>\n")


class PvdSeries:
    """A ParaView collection (.pvd) listing VTU frames with their times; rewritten atomically."""

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = Path(path)
        self.entries: list[tuple[float, str]] = []

    def add(self, time: float, frame: str | os.PathLike[str]) -> None:
        """Append a frame (path relative to the .pvd's folder) and rewrite the .pvd."""
        self.entries.append((time, Path(frame).as_posix()))
        lines = [
            '<?xml version="1.0"?>',
            '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
            "<Collection>",
            *(
                f'<DataSet timestep="{t!r}" group="" part="0" file={quoteattr(f)}/>'
                for t, f in self.entries
            ),
            "</Collection>",
            "</VTKFile>",
            "",
        ]
        atomic_write(self.path, "\n".join(lines).encode())
