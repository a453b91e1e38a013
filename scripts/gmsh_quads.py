"""Writes a surface of quadrilaterals as a gmsh 4.1 mesh (one entity, one physical group): the
format `interface_protocol::io::gmsh` reads, for the cases' mesh generators (`make_mesh.py`)."""
import sys


def write_quads(group, nodes, quads, out=sys.stdout):
    """`nodes`: (x, y, z) tuples; `quads`: 1-based node numbers in the order that gives the
    normal; `group`: the physical group's name (a cell set of the structure)."""
    lo = [min(p[k] for p in nodes) for k in range(3)]
    hi = [max(p[k] for p in nodes) for k in range(3)]
    w = out.write
    w("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n")
    w(f'$PhysicalNames\n1\n2 1 "{group}"\n$EndPhysicalNames\n')
    w(f"$Entities\n0 0 1 0\n1 {' '.join(map(str, lo + hi))} 1 1 0\n$EndEntities\n")
    w(f"$Nodes\n1 {len(nodes)} 1 {len(nodes)}\n2 1 0 {len(nodes)}\n")
    for i in range(len(nodes)):
        w(f"{i + 1}\n")
    for x, y, z in nodes:
        w(f"{x!r} {y!r} {z!r}\n")
    w("$EndNodes\n")
    w(f"$Elements\n1 {len(quads)} 1 {len(quads)}\n2 1 3 {len(quads)}\n")
    for e, q in enumerate(quads):
        w(" ".join(map(str, (e + 1, *q))) + "\n")
    w("$EndElements\n")
