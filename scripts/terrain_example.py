#!/usr/bin/python3
"""docs/terrain.md "Terrain through geodexd and Python": a GeoTIFF DEM through the geodex package.
usage: terrain_example.py HOST:PORT OUTDIR  (OUTDIR holds valley.tif: scripts/sample_dem.py)"""
import sys

import geodex

server, out = sys.argv[1], sys.argv[2]
with geodex.GeodexClient(server) as client:
    valley = client.upload(f"{out}/valley.tif", name="valley")              # a GeoTIFF: a DEM
    print(valley.terrain.crs_name)                                          # WGS 84 / UTM zone 32N
    dry = client.derive_mesh("meshes/valley", below=0.0, name="valley-dry")  # the lake as a barrier
    hut = geodex.lon_lat(10.2963, 46.0435)
    field = client.distance_field("meshes/valley-dry", [hut, geodex.map_point(603300, 5097900)])
    print(max(d for d in field.distances if d != float("inf")))             # the farthest reachable
    with open(f"{out}/isochrones-py.geojson", "wb") as f:
        f.write(client.export_gis("meshes/valley-dry", "isochrones", [hut], levels=[500, 1000]))
