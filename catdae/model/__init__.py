"""The model stage: a validated case -> what a step solves.

``mesh`` puts nodes on the exact catenary, ``formfind`` finds lengths from form targets,
``loading`` gathers the loads and masses a step holds and picks the mass model, ``assembly``
holds the DOF pattern and the step ``Model`` (element batches, supports, sparse scatter).
Imports the case and element stages only; knows nothing of solvers or output.
"""
