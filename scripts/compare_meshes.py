#!/usr/bin/env python3
# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# Compares two binary little-endian PLY meshes as sets of triangles by vertex position (each
# rotated to start at its least vertex, orientation kept), and their boundary edges (edges of
# one triangle) by position: equal up to order and welding. Then, as written: vertices, vertices
# at a position another vertex has (0 when welded) and open edges by vertex index (an unwelded
# seam counts its edges twice): equal counts for A and B mean B is welded as A is. Pure Python,
# no numpy; ~30 s per million triangles. Usage: compare_meshes.py A.ply B.ply
import struct, sys
T={'float':'f','float32':'f','uchar':'B','uint8':'B','int':'i','int32':'i','uint':'I','uint32':'I','double':'d','char':'b','short':'h','ushort':'H'}
def read(path):
    f=open(path,'rb'); elems=[]; fmt=None
    while True:
        line=f.readline().decode().strip()
        if line.startswith('format'): fmt=line.split()[1]
        elif line.startswith('element'):
            _,n,c=line.split(); elems.append([n,int(c),[]])
        elif line.startswith('property'):
            p=line.split()
            elems[-1][2].append(p[1:])
        elif line=='end_header': break
    assert fmt=='binary_little_endian', fmt
    data=f.read(); off=0; verts=[]; faces=[]
    for name,count,props in elems:
        if name=='vertex':
            s='<'+''.join(T[p[0]] for p in props); sz=struct.calcsize(s)
            xi=[i for i,p in enumerate(props) if p[-1] in('x','y','z')]
            for k in range(count):
                v=struct.unpack_from(s,data,off); off+=sz
                verts.append(tuple(v[i] for i in xi))
        elif name=='face':
            p=props[0]; cs='<'+T[p[1]]; isz=struct.calcsize('<'+T[p[2]])
            for k in range(count):
                n=struct.unpack_from(cs,data,off)[0]; off+=struct.calcsize(cs)
                idx=struct.unpack_from('<'+T[p[2]]*n,data,off); off+=isz*n
                faces.append(idx)
    return verts,faces
def tris(path):
    v,f=read(path); out=[]
    for t in f:
        tri=[v[i] for i in t]; m=tri.index(min(tri)); tri=tri[m:]+tri[:m]; out.append(tuple(tri))
    return sorted(out), v, f
def boundary(v,f):
    from collections import Counter
    c=Counter()
    for t in f:
        for k in range(3):
            a,b=v[t[k]],v[t[(k+1)%3]]
            c[(min(a,b),max(a,b))]+=1
    return set(e for e,n in c.items() if n==1)
a,va,fa=tris(sys.argv[1]); b,vb,fb=tris(sys.argv[2])
print('triangles', len(a), len(b), 'equal sets:', a==b)
if a!=b:
    sa,sb=set(a),set(b); print('only first', len(sa-sb), 'only second', len(sb-sa))
ba,bb=boundary(va,fa),boundary(vb,fb)
print('boundary edges', len(ba), len(bb), 'equal:', ba==bb)
def by_index(v,f):
    from collections import Counter
    c=Counter()
    for t in f:
        for k in range(3):
            a,b=t[k],t[(k+1)%3]
            c[(min(a,b),max(a,b))]+=1
    return sum(1 for n in c.values() if n==1)
print('vertices', len(va), len(vb), 'at a shared position', len(va)-len(set(va)), len(vb)-len(set(vb)))
oa,ob=by_index(va,fa),by_index(vb,fb)
print('open edges by index', oa, ob, 'equal:', oa==ob)
