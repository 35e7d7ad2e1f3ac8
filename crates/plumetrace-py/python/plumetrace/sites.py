"""A site's ocean data from xarray: currents and bathymetry held as ``xarray.Dataset`` objects,
flown through the scenario keys that read CF NetCDF files.

The datasets are written as NetCDF classic files (xarray's ``scipy`` engine, no C library) in a
directory of their own, and :func:`site_set` returns the overrides that point a scenario at them,
for :func:`plumetrace.run`'s ``set``::

    import xarray as xr
    import plumetrace
    from plumetrace.sites import site_set

    currents = xr.open_dataset("forecast.nc")[["uo", "vo"]].sel(depth=slice(0, 20))
    seabed = xr.open_dataset("gebco.nc")
    r = plumetrace.run("site.toml", set=site_set(currents, seabed, "site-data"))

The Rust reader finds the velocities and the depth by their CF ``standard_name`` (or the names
given to :func:`site_set`), as it does for any file; see the scenario page, "Rehearsing at a
site". Needs xarray and scipy.
"""

import os
from typing import Any, Dict, Optional, Union

PathLike = Union[str, "os.PathLike[str]"]

__all__ = ["site_set", "write_classic"]


def write_classic(ds: Any, path: PathLike) -> str:
    """Writes an ``xarray.Dataset`` as a NetCDF classic (CDF-2) file the scenario reader takes,
    and returns its path.

    64-bit integers, which the classic format cannot hold, are stored as 32-bit (an error if a
    value does not fit); times are encoded by xarray as ``<unit> since <date>``.
    """
    try:
        import xarray as xr
    except ImportError as e:  # pragma: no cover - the message is the point
        raise ImportError("plumetrace.sites needs xarray (pip install xarray scipy)") from e
    if not isinstance(ds, xr.Dataset):
        raise TypeError(f"expected an xarray.Dataset, got {type(ds).__name__}")
    ds = ds.copy()
    for name, var in ds.variables.items():
        if var.dtype.kind in "iu" and var.dtype.itemsize == 8:
            lo, hi = (int(var.values.min()), int(var.values.max())) if var.size else (0, 0)
            if lo < -(2**31) or hi >= 2**31:
                raise ValueError(
                    f"variable {name}: values {lo} to {hi} do not fit the classic format's "
                    "32-bit integers"
                )
            ds[name] = var.astype("int32")
    path = os.fspath(path)
    ds.to_netcdf(path, format="NETCDF3_64BIT", engine="scipy")
    return path


def site_set(
    currents: Any = None,
    bathymetry: Any = None,
    directory: PathLike = ".",
    *,
    u_variable: Optional[str] = None,
    v_variable: Optional[str] = None,
    depth_variable: Optional[str] = None,
) -> Dict[str, Any]:
    """Writes the datasets given into ``directory`` (``currents.nc``, ``seabed.nc``) and returns
    the scenario overrides that read them: ``flow.model``, ``flow.file`` (and
    ``flow.netcdf.u_variable``, ``v_variable`` if named) for the currents, ``bathymetry.file``
    (and ``bathymetry.variable``) for the seabed. Paths are absolute, so the overrides work
    wherever the scenario file is.
    """
    if currents is None and bathymetry is None:
        raise ValueError("give currents, bathymetry or both")
    directory = os.path.abspath(os.fspath(directory))
    os.makedirs(directory, exist_ok=True)
    out: Dict[str, Any] = {}
    if currents is not None:
        out["flow.model"] = "gridded"
        out["flow.file"] = write_classic(currents, os.path.join(directory, "currents.nc"))
        if u_variable is not None:
            out["flow.netcdf.u_variable"] = u_variable
        if v_variable is not None:
            out["flow.netcdf.v_variable"] = v_variable
    if bathymetry is not None:
        out["bathymetry.file"] = write_classic(bathymetry, os.path.join(directory, "seabed.nc"))
        if depth_variable is not None:
            out["bathymetry.variable"] = depth_variable
    return out
