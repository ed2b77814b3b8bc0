"""The output stage: labelled xarray datasets with CF attributes, netCDF files, figures and
VTK export. The only stage that builds xarray objects for results; it reads solver arrays and
never calls back into the solvers.
"""
