"""Names of mesh nodes, ``<cable>.<k>``: the interior nodes of a cable of n elements are
``<cable>.1`` .. ``<cable>.<n-1>`` (its ends are the named nodes of ``ends``). One formatter
and one parser, used by every stage (case checks, mesh, form-finding, studies, output)."""

from __future__ import annotations


def mesh_node(cable: str, k: int) -> str:
    """The name of interior node ``k`` of ``cable``."""
    return f"{cable}.{int(k)}"


def split_mesh_node(ref: str) -> tuple[str, str] | None:
    """``(cable, k as written)`` of a reference ``<cable>.<k>`` (split at the last dot), or None
    when it has no dot. Whether the cable exists and k is a valid index is the caller's to
    judge (``catdae.case.build_cables`` says why not)."""
    cable, dot, k = ref.rpartition(".")
    return (cable, k) if dot else None


def cable_of(ref: str) -> str:
    """The cable part of a mesh-node reference ("" without a dot)."""
    parts = split_mesh_node(ref)
    return parts[0] if parts else ""
