"""The solver stage: static (Newton), modal (eigenproblem) and transient (SUNDIALS IDA) steps.

``residual`` poses a transient for IDA (residual, analytic iteration matrix, consistent
start); ``transient`` drives IDA (the only module that imports sksundae). Solvers take a
``catdae.model`` Model and return arrays and solver statistics; xarray datasets are built in
``catdae.output``.
"""
