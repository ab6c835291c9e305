#!/usr/bin/env python3
"""Writes contrast_bar.vtu: a 4 x 1 x 1 mm hex8 bar of 8 x 2 x 2 cells whose
cell array "Material" is 1 for x < 2 mm and 2 beyond (the two bonded halves
of the stability suite's material-contrast case). ASCII VTU, no dependencies:
    python3 make_contrast_bar.py > contrast_bar.vtu
"""
nx, ny, nz = 8, 2, 2
lx, ly, lz = 4.0, 1.0, 1.0


def node(i, j, k):
    return i + (nx + 1) * (j + (ny + 1) * k)


points = [(lx * i / nx, ly * j / ny, lz * k / nz) for k in range(nz + 1) for j in range(ny + 1) for i in range(nx + 1)]
cells, tags = [], []
for k in range(nz):
    for j in range(ny):
        for i in range(nx):
            cells.append([node(i, j, k), node(i + 1, j, k), node(i + 1, j + 1, k), node(i, j + 1, k),
                          node(i, j, k + 1), node(i + 1, j, k + 1), node(i + 1, j + 1, k + 1), node(i, j + 1, k + 1)])
            tags.append(1 if (i + 0.5) * lx / nx < lx / 2 else 2)
print('<?xml version="1.0"?>')
print('<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">')
print('<UnstructuredGrid><Piece NumberOfPoints="%d" NumberOfCells="%d">' % (len(points), len(cells)))
print('<Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">')
print('\n'.join('%g %g %g' % p for p in points))
print('</DataArray></Points>')
print('<Cells><DataArray type="Int64" Name="connectivity" format="ascii">')
print('\n'.join(' '.join(map(str, c)) for c in cells))
print('</DataArray><DataArray type="Int64" Name="offsets" format="ascii">')
print(' '.join(str(8 * (n + 1)) for n in range(len(cells))))
print('</DataArray><DataArray type="UInt8" Name="types" format="ascii">')
print(' '.join('12' for _ in cells))
print('</DataArray></Cells>')
print('<CellData><DataArray type="Int32" Name="Material" format="ascii">')
print(' '.join(map(str, tags)))
print('</DataArray></CellData>')
print('</Piece></UnstructuredGrid></VTKFile>')
