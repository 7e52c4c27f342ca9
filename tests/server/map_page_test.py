#!/usr/bin/python3
"""geodexd's map page (GET / of --http_listen) in a real browser: headless Chromium driven by
Selenium against a geodexd this test starts on 127.0.0.1 (ports it picks), with a DEM uploaded
over HTTP. The deep link draws one route and the isochrones at two levels; a click sequence on
the map draws another route; the browser's log has no SEVERE entry. Bounded (60 s per wait).
GEODEX_MAP_SCREENSHOT=FILE saves a picture of the page (docs/map.png is one).
Env: GEODEXD. Stops only the geodexd it started.
"""
import json
import math
import os
import re
import subprocess
import tempfile
import time
import unittest
import urllib.request

from osgeo import gdal, osr
from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import WebDriverWait

GEODEXD = os.environ["GEODEXD"]
X0, Y1, CELL, W, H = 500000.0, 5000000.0, 10.0, 80, 60  # UTM 33N, 10 m cells


def make_dem(path):
    ds = gdal.GetDriverByName("GTiff").Create(path, W, H, 1, gdal.GDT_Float32)
    ds.SetGeoTransform([X0, CELL, 0, Y1, 0, -CELL])
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(32633)
    ds.SetProjection(srs.ExportToWkt())
    band = ds.GetRasterBand(1)
    rows = [[30 * math.sin(i / 9.0) * math.cos(j / 7.0) + 0.2 * i for i in range(W)]
            for j in range(H)]
    import numpy
    band.WriteArray(numpy.array(rows, dtype=numpy.float32))
    ds = None


class MapPageTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        log = os.path.join(cls.tmp.name, "geodexd.log")
        cls.log = open(log, "w")
        cls.proc = subprocess.Popen(
            [GEODEXD, "--listen", "127.0.0.1:0", "--http_listen", "127.0.0.1:0",
             "--metrics_listen", "", "--samples=false", "--pool-threads", "2",
             "--shutdown_grace_seconds", "2"], stdout=cls.log, stderr=subprocess.STDOUT)
        cls.http = None
        for _ in range(600):
            found = re.search(r"HTTP/JSON API on http://127\.0\.0\.1:(\d+)/", open(log).read())
            if found:
                cls.http = "http://127.0.0.1:" + found.group(1)
                break
            if cls.proc.poll() is not None:
                break
            time.sleep(0.05)
        assert cls.http, "geodexd did not start:\n" + open(log).read()
        dem = os.path.join(cls.tmp.name, "hills.tif")
        make_dem(dem)
        request = urllib.request.Request(
            cls.http + "/v1/meshes?display_name=hills&format=MESH_FORMAT_GEOTIFF",
            data=open(dem, "rb").read(), headers={"Content-Type": "image/tiff"}, method="POST")
        with urllib.request.urlopen(request, timeout=60) as answer:
            cls.mesh = json.load(answer)
        options = webdriver.ChromeOptions()
        for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                     "--window-size=1200,800"):
            options.add_argument(flag)
        options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
        cls.driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)
        cls.driver.set_page_load_timeout(60)

    @classmethod
    def tearDownClass(cls):
        cls.driver.quit()
        cls.proc.terminate()
        try:
            cls.proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            cls.proc.kill()
        cls.log.close()
        cls.tmp.cleanup()

    def count(self, css):
        return len(self.driver.find_elements(By.CSS_SELECTOR, css))

    def wait_for(self, condition, what):
        try:
            WebDriverWait(self.driver, 60).until(lambda d: condition())
        except Exception:
            status = self.driver.find_element(By.ID, "status").text
            self.fail(f"{what}: not within 60 s (page says: {status!r}); browser log: "
                      f"{self.driver.get_log('browser')}")

    def severe(self):
        return [e for e in self.driver.get_log("browser") if e["level"] == "SEVERE"]

    def test_deep_link_draws_the_route_and_the_isochrones(self):
        self.assertIsNotNone(self.mesh.get("terrain"))
        # Start and goal in map coordinates; 1 m/s: levels 100 s and 200 s are 100 m and 200 m.
        self.driver.get(self.http + "/?mesh=hills&from=500205,4999705&to=500605,4999405"
                        "&levels=100,200&speed=constant:3.6")
        self.wait_for(lambda: self.count(".geodex-route") >= 1 and
                      self.count(".geodex-isochrone") >= 2, "a route and two isochrones")
        self.assertEqual(self.count("path.geodex-route"), 1)
        result = self.driver.find_element(By.ID, "result").text
        self.assertRegex(result, r"Route: \d+\.\d m, \d+\.\d min")
        length = float(re.search(r"Route: ([\d.]+) m", result).group(1))
        self.assertGreater(length, 499)  # at least the straight 500 m between the points
        legend = self.driver.find_element(By.CLASS_NAME, "geodex-legend").text
        self.assertIn("min", legend)  # the unit of the levels, with a speed
        self.assertIn("N", self.driver.find_element(By.CLASS_NAME, "geodex-north").text)
        self.assertTrue(self.driver.find_elements(By.CLASS_NAME, "leaflet-control-scale"))
        links = [a.text for a in self.driver.find_elements(By.CSS_SELECTOR, "#downloads a")]
        self.assertIn("isochrones (GeoJSON)", links)
        self.assertIn("route (GeoJSON)", links)
        self.assertEqual(self.severe(), [])
        shot = os.environ.get("GEODEX_MAP_SCREENSHOT")
        if shot:
            self.driver.save_screenshot(shot)

    def test_clicks_draw_isochrones_then_a_route(self):
        self.driver.get(self.http + "/?mesh=hills&levels=150,300")
        self.wait_for(lambda: self.count(".leaflet-image-layer") >= 1, "the hillshade")
        self.assertEqual(self.count(".geodex-route"), 0)
        area = self.driver.find_element(By.ID, "map")
        width, height = area.size["width"], area.size["height"]
        ActionChains(self.driver).move_to_element_with_offset(
            area, -width // 6, -height // 8).click().perform()
        self.wait_for(lambda: self.count(".geodex-isochrone") >= 2, "isochrones after a click")
        ActionChains(self.driver).move_to_element_with_offset(
            area, width // 6, height // 8).click().perform()
        self.wait_for(lambda: self.count(".geodex-route") >= 1, "a route after a second click")
        self.assertIn("from=", self.driver.current_url)  # the view is a link
        self.assertIn("to=", self.driver.current_url)
        self.assertEqual(self.severe(), [])

    def test_the_page_is_served_with_its_files_and_a_content_policy(self):
        with urllib.request.urlopen(self.http + "/", timeout=30) as page:
            self.assertIn("text/html", page.headers["Content-Type"])
            self.assertIn("default-src 'self'", page.headers["Content-Security-Policy"])
            html = page.read().decode()
        for path in re.findall(r'(?:src|href)="(/[^"]+)"', html):
            with urllib.request.urlopen(self.http + path, timeout=30) as asset:
                self.assertEqual(asset.status, 200, path)


if __name__ == "__main__":
    unittest.main(verbosity=2)
