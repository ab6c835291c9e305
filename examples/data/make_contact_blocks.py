#!/usr/bin/env python3
"""Writes the two blocks of examples/contact_blocks.yaml: block_lower.vtu, a
1 x 1 x 0.5 mm hex8 block of 4 x 4 x 2 cells at 0 <= z <= 0.5, and
block_upper.vtu, 3 x 3 x 2 cells at 0.5 <= z <= 1 (non-matching at the
interface z = 0.5). ASCII VTU, no dependencies:
    python3 make_contact_blocks.py   # in examples/data
"""


def block(nx, ny, nz, z0, path):
    def node(i, j, k):
        return i + (nx + 1) * (j + (ny + 1) * k)

    points = [(i / nx, j / ny, z0 + 0.5 * k / nz) for k in range(nz + 1) for j in range(ny + 1) for i in range(nx + 1)]
    cells = [[node(i, j, k), node(i + 1, j, k), node(i + 1, j + 1, k), node(i, j + 1, k),
              node(i, j, k + 1), node(i + 1, j, k + 1), node(i + 1, j + 1, k + 1), node(i, j + 1, k + 1)]
             for k in range(nz) for j in range(ny) for i in range(nx)]
    with open(path, "w") as f:
        w = f.write
        w('<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">\n')
        w('<UnstructuredGrid><Piece NumberOfPoints="%d" NumberOfCells="%d">\n' % (len(points), len(cells)))
        w('<Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">\n')
        w('\n'.join('%.17g %.17g %.17g' % p for p in points))
        w('\n</DataArray></Points>\n<Cells><DataArray type="Int64" Name="connectivity" format="ascii">\n')
        w('\n'.join(' '.join(map(str, c)) for c in cells))
        w('\n</DataArray><DataArray type="Int64" Name="offsets" format="ascii">\n')
        w(' '.join(str(8 * (n + 1)) for n in range(len(cells))))
        w('\n</DataArray><DataArray type="UInt8" Name="types" format="ascii">\n')
        w(' '.join('12' for _ in cells))
        w('\n</DataArray></Cells>\n</Piece></UnstructuredGrid></VTKFile>\n')


block(4, 4, 2, 0.0, "block_lower.vtu")
block(3, 3, 2, 0.5, "block_upper.vtu")
