#!/usr/bin/python3
"""Writes a sample DEM as a GeoTIFF: 120 x 100 cells of 30 m in UTM zone 32N (WGS 84), near
10.3 E 46.0 N: two ridges, a valley, and a lake whose surface lies below 0 m (to try
--barrier-below 0). Heights in metres, float32, nodata -9999 in one corner (a data gap).

usage: /usr/bin/python3 scripts/sample_dem.py OUT.tif   (needs python3-gdal and python3-numpy)
"""
import sys

import numpy as np
from osgeo import gdal, osr

gdal.UseExceptions()
out = sys.argv[1]
W, H, CELL = 120, 100, 30.0
x0, y0 = 600000.0, 5100000.0  # top-left corner, UTM 32N
i, j = np.meshgrid(np.arange(W), np.arange(H))
x, y = i * CELL, j * CELL
ridge1 = 180 * np.exp(-((x - 900) ** 2) / (2 * 500.0 ** 2))
ridge2 = 140 * np.exp(-((y - 2200) ** 2) / (2 * 350.0 ** 2)) / (1 + np.exp(-(x - 1500) / 120.0))
slope = 0.02 * x
lake = -140 * np.exp(-(((x - 2600) ** 2) / (2 * 300.0 ** 2) + ((y - 1000) ** 2) / (2 * 250.0 ** 2)))
z = 20 + ridge1 + ridge2 + slope + lake + 4 * np.sin(x / 170.0) * np.cos(y / 230.0)
z[-12:, :10] = -9999  # a data gap in the bottom-left corner
ds = gdal.GetDriverByName("GTiff").Create(out, W, H, 1, gdal.GDT_Float32, ["COMPRESS=DEFLATE"])
ds.SetGeoTransform((x0, CELL, 0, y0, 0, -CELL))
srs = osr.SpatialReference()
srs.ImportFromEPSG(32632)
ds.SetProjection(srs.ExportToWkt())
band = ds.GetRasterBand(1)
band.SetNoDataValue(-9999)
band.SetUnitType("m")
band.WriteArray(z.astype(np.float32))
ds = None
print(out)
