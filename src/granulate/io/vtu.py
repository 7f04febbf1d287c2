"""VTK XML unstructured grids (.vtu) of nodes, parallel ones (.pvtu: pieces written by several
processes) and .pvd time series, for ParaView.

Binary appended data, zlib-compressed in blocks (header_type UInt64), as VTK writes it:
each array is [number of blocks, block size, size of the last block, compressed sizes...]
followed by the compressed blocks. Nodes are written as VTK_VERTEX cells. A .pvtu lists its
pieces' files and the arrays each holds; granulate's pieces carry each node's number in the
whole run (NODE_ID), by which read_vtu_point_data puts their nodes back in order.
"""

from __future__ import annotations

import os
import zlib
from base64 import b64decode
from collections.abc import Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from xml.etree import ElementTree

import numpy as np
from numpy.typing import NDArray

from granulate.errors import InputError
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


#: What an XML attribute's value cannot hold as itself, and its reference.
_ESCAPES = str.maketrans(
    {
        "&": "&amp;",
        "<": "&lt;",
        ">": "&gt;",
        '"': "&quot;",
        "\n": "&#10;",
        "\r": "&#13;",
        "\t": "&#9;",
    }
)


def _quoted(text: str) -> str:
    """`text` as a double-quoted XML attribute value (xml.sax.saxutils.quoteattr's job, whose
    import brings urllib and http.client: 40 ms of every granulate process's start)."""
    return '"' + text.translate(_ESCAPES) + '"'


#: zlib level: 1 compresses simulation fields nearly as well as 6, several times faster; arrays
#: that do not compress are stored (level 0) so that a frame of a million nodes takes well under
#: a second.
_LEVEL = 1
_POOL: ThreadPoolExecutor | None = None


def _pool() -> ThreadPoolExecutor:
    """Threads for compressing blocks (zlib releases the GIL): one per core."""
    global _POOL
    if _POOL is None:
        _POOL = ThreadPoolExecutor(max_workers=max(1, os.cpu_count() or 1))
    return _POOL


def _blocks(array: NDArray[np.generic]) -> list[memoryview]:
    if array.size == 0:  # an empty array is one empty block (memoryview cannot cast it)
        return [memoryview(b"")]
    raw = memoryview(
        np.ascontiguousarray(array).astype(array.dtype.newbyteorder("<"), copy=False)
    ).cast("B")
    return [raw[k : k + _BLOCK] for k in range(0, len(raw), _BLOCK)] or [memoryview(b"")]


def _level(blocks: list[memoryview]) -> int:
    """zlib level for an array: 1, or 0 (stored, no compression work) when its middle block does
    shrink to half (the low bits of doubles are noise; IDs, flags and cells compress)."""
    sample = blocks[len(blocks) // 2]  # the middle: edges of a field are often special
    if len(sample) == 0:
        return _LEVEL
    return _LEVEL if len(zlib.compress(sample, _LEVEL)) < 0.5 * len(sample) else 0


def _compress_all(arrays: list[NDArray[np.generic]]) -> list[list[bytes]]:
    """Each array as VTK's compressed block stream (its header, then its compressed blocks, as
    separate chunks: a frame's tens of MB are written without being joined); all blocks of all
    arrays compressed in parallel, in order (the output does not depend on the thread count)."""
    blocks = [_blocks(a) for a in arrays]
    levels = [_level(group) for group in blocks]
    flat = [(b, level) for group, level in zip(blocks, levels, strict=True) for b in group]
    packed = list(_pool().map(lambda item: zlib.compress(item[0], item[1]), flat, chunksize=8))
    out = []
    start = 0
    for group in blocks:
        mine = packed[start : start + len(group)]
        start += len(group)
        header = np.array(
            [len(group), _BLOCK, len(group[-1]), *(len(p) for p in mine)], dtype="<u8"
        )
        out.append([header.tobytes(), *mine])
    return out


_VTK_VERTEX, _VTK_LINE = 1, 3


def write_vtu(
    path: str | os.PathLike[str],
    points: NDArray[np.float64],
    point_data: Mapping[str, NDArray[np.generic]],
    *,
    lines: NDArray[np.int64] | None = None,
    cell_data: Mapping[str, NDArray[np.generic]] | None = None,
) -> None:
    """Write points and their fields as a .vtu file (atomically): each point a vertex cell, or
    with `lines` ((k, 2) point indices) line cells with `cell_data`.

    Args:
        path: target file.
        points: (n, 3) positions.
        point_data: name -> (n,) or (n, k) array; dtypes float64/float32/int64/int32/uint32/uint8.
        lines: (k, 2) point indices of line cells (instead of one vertex per point).
        cell_data: name -> (k,) or (k, m) array, one row per line.
    """
    n = len(points)
    if lines is None:
        connectivity, cells, kind = np.arange(n, dtype=np.int64), n, _VTK_VERTEX
    else:
        connectivity, cells, kind = np.asarray(lines, dtype=np.int64).ravel(), len(lines), _VTK_LINE
    per_cell = 1 if lines is None else 2
    entries: list[tuple[str, str, NDArray[np.generic]]] = [
        ("point", name, np.asarray(values)) for name, values in point_data.items()
    ]
    entries += [("cell", name, np.asarray(values)) for name, values in (cell_data or {}).items()]
    entries.append(("points", "", np.asarray(points, dtype=np.float64).reshape(-1, 3)))
    entries.append(("cells", "connectivity", connectivity))
    entries.append(("cells", "offsets", np.arange(1, cells + 1, dtype=np.int64) * per_cell))
    entries.append(("cells", "types", np.full(cells, kind, dtype=np.uint8)))
    entries = [
        (section, name, values if values.dtype in _VTK_TYPES else values.astype(np.float64))
        for section, name, values in entries
    ]
    payloads = _compress_all([values for _, _, values in entries])
    descriptors: list[str] = []
    offset = 0
    for (_, name, values), payload in zip(entries, payloads, strict=True):
        components = "" if values.ndim == 1 else f' NumberOfComponents="{values.shape[1]}"'
        name_attr = f" Name={_quoted(name)}" if name else ""
        descriptors.append(
            f'<DataArray type="{_VTK_TYPES[values.dtype]}"{name_attr}{components} '
            f'format="appended" offset="{offset}"/>'
        )
        offset += sum(len(chunk) for chunk in payload)
    point_count, cell_count = len(point_data), len(cell_data or {})
    geometry = point_count + cell_count

    xml = [
        '<?xml version="1.0"?>',
        '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
        'header_type="UInt64" compressor="vtkZLibDataCompressor">',
        "<UnstructuredGrid>",
        f'<Piece NumberOfPoints="{n}" NumberOfCells="{cells}">',
        "<PointData>",
        *descriptors[:point_count],
        "</PointData>",
        "<CellData>",
        *descriptors[point_count:geometry],
        "</CellData>",
        "<Points>",
        descriptors[geometry],
        "</Points>",
        "<Cells>",
        *descriptors[geometry + 1 :],
        "</Cells>",
        "</Piece>",
        "</UnstructuredGrid>",
        '<AppendedData encoding="raw">',
    ]
    head = "\n".join(xml).encode() + b"\n_"
    tail = b"\n</AppendedData>\n</VTKFile>\n"
    atomic_write(path, [head, *(chunk for payload in payloads for chunk in payload), tail])


#: The point array of a frame's piece that numbers its nodes as the whole run does.
NODE_ID = "Node_ID"


def write_pvtu(
    path: str | os.PathLike[str],
    pieces: Sequence[str],
    point_arrays: Sequence[tuple[str, np.dtype[np.generic], int]],
) -> None:
    """Write a parallel VTU (.pvtu, atomically) listing `pieces` (.vtu files of points as
    write_vtu writes them, paths relative to the .pvtu's folder) whose point data holds
    `point_arrays` (name, dtype, components) each."""
    arrays = [
        f'<PDataArray type="{_VTK_TYPES[np.dtype(dtype)]}" Name={_quoted(name)}'
        + (f' NumberOfComponents="{components}"' if components > 1 else "")
        + "/>"
        for name, dtype, components in point_arrays
    ]
    xml = [
        '<?xml version="1.0"?>',
        '<VTKFile type="PUnstructuredGrid" version="1.0" byte_order="LittleEndian" '
        'header_type="UInt64">',
        '<PUnstructuredGrid GhostLevel="0">',
        "<PPointData>",
        *arrays,
        "</PPointData>",
        "<PPoints>",
        '<PDataArray type="Float64" NumberOfComponents="3"/>',
        "</PPoints>",
        *(f"<Piece Source={_quoted(Path(piece).as_posix())}/>" for piece in pieces),
        "</PUnstructuredGrid>",
        "</VTKFile>",
        "",
    ]
    atomic_write(path, "\n".join(xml).encode())


class PvdSeries:
    """A ParaView collection (.pvd) listing VTU frames with their times; rewritten atomically."""

    def __init__(self, path: str | os.PathLike[str]) -> None:
        self.path = Path(path)
        self.entries: list[tuple[float, str]] = []

    def add(self, time: float, frame: str | os.PathLike[str]) -> None:
        """Append a frame (path relative to the .pvd's folder) and rewrite the .pvd."""
        self.entries.append((time, Path(frame).as_posix()))
        self.write()

    def write(self) -> None:
        """Write the .pvd listing the entries."""
        lines = [
            '<?xml version="1.0"?>',
            '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
            "<Collection>",
            *(
                f'<DataSet timestep="{t!r}" group="" part="0" file={_quoted(f)}/>'
                for t, f in self.entries
            ),
            "</Collection>",
            "</VTKFile>",
            "",
        ]
        atomic_write(self.path, "\n".join(lines).encode())


def read_pvd(path: str | os.PathLike[str]) -> list[tuple[float, Path]]:
    """The (time, frame path) entries of a .pvd collection, paths resolved against its folder.
    Raises InputError when it is missing or not a collection."""
    target = Path(path)
    try:
        root = ElementTree.parse(target).getroot()
        return [
            (float(entry.get("timestep", "nan")), target.parent / entry.get("file", ""))
            for entry in root.iter("DataSet")
        ]
    except OSError as error:
        raise InputError(f"cannot read {target}: {error.strerror or error}") from None
    except (ElementTree.ParseError, ValueError) as error:
        raise InputError(f"{target} is not a ParaView collection (.pvd): {error}") from None


_NUMPY_TYPES = {
    "Float64": "<f8",
    "Float32": "<f4",
    "Int64": "<i8",
    "Int32": "<i4",
    "UInt64": "<u8",
    "UInt32": "<u4",
    "UInt8": "<u1",
    "Int8": "<i1",
}


@dataclass(frozen=True)
class _Appended:
    """A VTU file's appended data: its bytes (after the "_"), their encoding, the block header's
    integer type and whether the arrays are zlib blocks (VTK's vtkZLibDataCompressor)."""

    data: bytes
    base64: bool
    header: str  # "<u4" or "<u8"
    compressed: bool

    def decode(self, chunk: bytes) -> bytes:
        return b64decode(chunk) if self.base64 else chunk

    def array_bytes(self, offset: int) -> bytes:
        """The bytes of the array at `offset`: [size] data, or zlib blocks."""
        return self._zlib_blocks(offset) if self.compressed else self._plain(offset)

    def _plain(self, offset: int) -> bytes:
        header_size = np.dtype(self.header).itemsize
        appended = self.data
        if self.base64:  # header and data encoded together
            size_chars = 4 * -(-header_size // 3)
            head = self.decode(appended[offset : offset + size_chars])[:header_size]
            size = int(np.frombuffer(head, self.header)[0])
            chars = 4 * -(-(header_size + size) // 3)
            return self.decode(appended[offset : offset + chars])[header_size : header_size + size]
        size = int(np.frombuffer(appended[offset : offset + header_size], self.header)[0])
        return appended[offset + header_size : offset + header_size + size]

    def _zlib_blocks(self, offset: int) -> bytes:
        """[count, block size, last size, compressed sizes...] then the blocks."""
        header, header_size = self.header, np.dtype(self.header).itemsize
        appended = self.data
        if self.base64:
            head_chars = 3 * header_size
            first = self.decode(appended[offset : offset + 4 * -(-head_chars // 3)])
            count = int(np.frombuffer(first[:header_size], header)[0])
            table_bytes = (3 + count) * header_size
            table_chars = 4 * -(-table_bytes // 3)
            table = np.frombuffer(
                self.decode(appended[offset : offset + table_chars])[:table_bytes], header
            )
            blocks_chars = 4 * -(-int(table[3:].sum()) // 3)
            payload = self.decode(
                appended[offset + table_chars : offset + table_chars + blocks_chars]
            )
        else:
            count = int(np.frombuffer(appended[offset : offset + header_size], header)[0])
            table = np.frombuffer(appended[offset : offset + (3 + count) * header_size], header)
            at = offset + (3 + count) * header_size
            payload = appended[at : at + int(table[3:].sum())]
        out, position = [], 0
        for size in table[3:]:
            out.append(zlib.decompress(payload[position : position + int(size)]))
            position += int(size)
        return b"".join(out)


def _split_appended(data: bytes) -> tuple[bytes, bytes, bool]:
    """A VTU file's XML (closed after its AppendedData is cut off), the appended bytes and
    whether they are base64."""
    start = data.find(b"<AppendedData")
    if start < 0:
        return data, b"", False
    tag_end = data.index(b">", start)
    base64 = b'encoding="base64"' in data[start:tag_end]
    body_start = data.index(b"_", tag_end) + 1
    body_end = data.rfind(b"</AppendedData>")
    appended = data[body_start:body_end]
    return data[:start] + b"</VTKFile>", appended.strip() if base64 else appended, base64


def _data_array(element: ElementTree.Element, appended: _Appended, source: Path) -> NDArray:
    """The values of one DataArray (appended or ASCII), (n, components) when it has several."""
    kind = element.get("type", "")
    if kind not in _NUMPY_TYPES:
        raise InputError(
            f"{source}: array {element.get('Name')!r} of type {kind!r} is not supported"
        )
    fmt = element.get("format", "ascii")
    if fmt == "appended":
        values = np.frombuffer(
            appended.array_bytes(int(element.get("offset", "0"))), _NUMPY_TYPES[kind]
        )
    elif fmt == "ascii":
        values = np.array((element.text or "").split(), dtype=_NUMPY_TYPES[kind])
    else:
        raise InputError(f"{source}: {fmt!r} arrays are not supported (use appended or ascii)")
    components = int(element.get("NumberOfComponents", "1"))
    return values.reshape(-1, components) if components > 1 else values.copy()


def read_vtu_point_data(
    path: str | os.PathLike[str],
) -> tuple[NDArray[np.float64], dict[str, NDArray[np.generic]]]:
    """Points and point data of a .vtu file: appended data (raw or base64, plain or with VTK's
    zlib blocks, UInt32 or UInt64 headers) or inline ASCII arrays; this writer's frames and
    PeriDEM's output files. A .pvtu's pieces are read and joined, in the whole run's node order
    when every piece numbers its nodes (NODE_ID, then left out), else in piece order. Raises
    InputError naming the problem otherwise."""
    source = Path(path)
    if source.suffix == ".pvtu":
        return _read_pvtu(source)
    try:
        data = source.read_bytes()
    except OSError as error:
        raise InputError(f"cannot read {source}: {error}") from None
    xml_text, appended_data, base64 = _split_appended(data)
    try:
        root = ElementTree.fromstring(xml_text)
    except ElementTree.ParseError as error:
        raise InputError(f"{source} is not a VTU file: {error}") from None
    if root.get("compressor") not in (None, "vtkZLibDataCompressor"):
        raise InputError(f"{source}: compressor {root.get('compressor')} is not supported")
    appended = _Appended(
        appended_data,
        base64,
        "<u8" if root.get("header_type") == "UInt64" else "<u4",
        root.get("compressor") == "vtkZLibDataCompressor",
    )
    piece = root.find("UnstructuredGrid/Piece")
    if piece is None:
        raise InputError(f"{source} has no UnstructuredGrid piece")
    points_element = piece.find("Points/DataArray")
    if points_element is None:
        raise InputError(f"{source} has no points")
    try:
        points = np.asarray(_data_array(points_element, appended, source), dtype=np.float64)
        points = points.reshape(-1, 3)
        point_data = {
            element.get("Name", ""): _data_array(element, appended, source)
            for element in piece.findall("PointData/DataArray")
        }
    except (ValueError, IndexError, zlib.error) as error:
        raise InputError(f"{source}: damaged data ({error})") from None
    return points, point_data


def _read_pvtu(
    source: Path,
) -> tuple[NDArray[np.float64], dict[str, NDArray[np.generic]]]:
    """A .pvtu's pieces joined (read_vtu_point_data)."""
    try:
        root = ElementTree.parse(source).getroot()
    except OSError as error:
        raise InputError(f"cannot read {source}: {error.strerror or error}") from None
    except ElementTree.ParseError as error:
        raise InputError(f"{source} is not a parallel VTU file: {error}") from None
    names = [piece.get("Source", "") for piece in root.iter("Piece")]
    if root.get("type") != "PUnstructuredGrid" or not names:
        raise InputError(f"{source} is not a parallel VTU file with pieces")
    pieces = [read_vtu_point_data(source.parent / name) for name in names]
    fields = set(pieces[0][1])
    if any(set(data) != fields for _, data in pieces):
        raise InputError(f"{source}: its pieces hold different point arrays")
    points = np.concatenate([points for points, _ in pieces])
    data = {name: np.concatenate([d[name] for _, d in pieces]) for name in pieces[0][1]}
    numbers = data.pop(NODE_ID, None)
    if numbers is None:
        return points, data
    order = np.argsort(numbers, kind="stable")
    if not np.array_equal(numbers[order], np.arange(len(numbers))):
        raise InputError(f"{source}: its pieces' {NODE_ID}s are not the nodes 0 .. n-1 once each")
    return points[order], {name: values[order] for name, values in data.items()}
