"""The element stage: Irvine's elastic catenary as a finite element (docs/theory.md §2-§6).

Owns the compiled kernels (``catenary``: the chord -> end forces, flexibility, stiffness,
G(s), N(s); ``mass``: mass, ∂M/∂c and dynamic forces; ``residual_kernel``: the one pass of a
transient residual over all elements), their on-disk cache (``cache``) and the batch objects
``Elements``, ``ElementState`` and ``PointLoads`` (``elements``). Pure numerics: no case files,
no meshes, no I/O, no imports from later stages.
"""
