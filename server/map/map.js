// geodex's map page (served by geodexd's HTTP port at /; docs/service.md, "The map page"). Plain
// JavaScript over the HTTP/JSON API: the DEM's map coordinates are Leaflet's simple CRS (metres
// east and north, no projection), the hillshade is drawn here from the mesh's own triangles
// (:getMeshGeometry), isochrones and routes are ExportGis GeoJSON in the raster's CRS.
// Deep link: /?mesh=ID&from=X,Y&to=X,Y&levels=600,1200&speed=constant:3.6
(function () {
  'use strict';
  var params = new URLSearchParams(window.location.search);
  var map = L.map('map', {crs: L.CRS.Simple, minZoom: -8, maxZoom: 8, zoomSnap: 0.25});
  var colors = ['#1a9850', '#91cf60', '#fee08b', '#fc8d59', '#d73027', '#762a83'];
  var state = {mesh: null, terrain: null, from: null, to: null, layers: [], hillshade: null,
               markers: [], downloads: []};
  var statusEl = document.getElementById('status');
  var resultEl = document.getElementById('result');
  var downloadsEl = document.getElementById('downloads');
  var meshSelect = document.getElementById('mesh');
  var levelsInput = document.getElementById('levels');
  var speedSelect = document.getElementById('speed');

  function say(text, isError) {
    statusEl.textContent = text;
    statusEl.className = isError ? 'error' : '';
  }

  // One call of the API; rejects with the google.rpc.Status message.
  function api(method, path, body) {
    var init = {method: method, headers: {}};
    if (body !== undefined) {
      init.headers['Content-Type'] = 'application/json';
      init.body = JSON.stringify(body);
    }
    return fetch(path, init).then(function (response) {
      var type = response.headers.get('Content-Type') || '';
      if (!response.ok) {  // a google.rpc.Status
        return response.json().then(function (status) {
          throw new Error(status.message || response.statusText);
        });
      }
      // JSON answers parsed; files (GeoJSON, GeoTIFF) as they are.
      return type.indexOf('application/json') === 0 ? response.json() : response.blob();
    });
  }

  function meshPath(suffix) {
    return '/v1/meshes/' + encodeURIComponent(state.mesh) + (suffix || '');
  }

  // Levels: "600,1200" or "10min,20min" (minutes with a speed: seconds on the wire).
  function levels() {
    return levelsInput.value.split(',').map(function (s) {
      s = s.trim();
      var minutes = /min$/.test(s);
      var v = parseFloat(s);
      return minutes ? v * 60 : v;
    }).filter(function (v) { return isFinite(v) && v > 0; });
  }

  function speedOptions() {
    var speed = speedSelect.value;
    if (!speed) return {};
    if (speed === 'tobler') return {travel: {speedModel: 'SPEED_MODEL_TOBLER'}};
    var kmh = parseFloat(speed.split(':')[1]);
    return {travel: {speed_kmh: kmh}};
  }

  function unit() { return speedSelect.value ? 's' : 'm'; }

  function mapPoint(latlng) { return {mapPoint: {x: latlng.lng, y: latlng.lat}}; }

  function geoJsonLayer(data, className, style) {
    return L.geoJSON(data, {
      coordsToLatLng: function (c) { return L.latLng(c[1], c[0]); },
      style: function (feature) { return Object.assign({className: className}, style(feature)); }
    });
  }

  function clearLayers() {
    state.layers.forEach(function (layer) { map.removeLayer(layer); });
    state.layers = [];
    state.downloads.forEach(function (url) { URL.revokeObjectURL(url); });
    state.downloads = [];
    downloadsEl.textContent = '';
    resultEl.textContent = '';
  }

  function offerDownload(label, blob, fileName) {
    var url = URL.createObjectURL(blob);
    state.downloads.push(url);
    var link = document.createElement('a');
    link.href = url;
    link.download = fileName;
    link.textContent = label;
    downloadsEl.appendChild(link);
    downloadsEl.appendChild(document.createElement('br'));
  }

  function updateLink() {
    var p = new URLSearchParams();
    if (state.mesh) p.set('mesh', state.mesh);
    if (state.from) p.set('from', state.from.lng + ',' + state.from.lat);
    if (state.to) p.set('to', state.to.lng + ',' + state.to.lat);
    p.set('levels', levelsInput.value);
    if (speedSelect.value) p.set('speed', speedSelect.value);
    window.history.replaceState(null, '', '/?' + p.toString());
  }

  // --- the legend, the north arrow and the scale
  var legend = L.control({position: 'bottomright'});
  legend.onAdd = function () {
    this.div = L.DomUtil.create('div', 'geodex-legend');
    return this.div;
  };
  legend.update = function (values) {
    var rows = values.map(function (v, k) {
      var shown = unit() === 's' && v >= 60 ? (v / 60).toFixed(1) + ' min' : v + ' ' + unit();
      return '<i style="background:' + colors[k % colors.length] + '"></i>within ' + shown;
    });
    rows.push('<b>&#8212;</b> route (exact)');
    this.div.innerHTML = rows.join('<br>');
  };
  legend.addTo(map);
  var north = L.control({position: 'topright'});
  north.onAdd = function () {
    var div = L.DomUtil.create('div', 'geodex-north');
    div.innerHTML = '&#8593;<br>N';
    div.title = 'grid north of the DEM\'s CRS';
    return div;
  };
  north.addTo(map);
  L.control.scale({imperial: false}).addTo(map);

  // --- the hillshade, from the mesh's triangles (light from the north-west, 45 degrees up)
  function drawHillshade(geometry, terrain) {
    var gt = terrain.geotransform, scale = terrain.horizontalScale || 1;
    var x0 = gt[0], y1 = gt[3];
    var x1 = gt[0] + terrain.gridWidth * gt[1], y0 = gt[3] + terrain.gridHeight * gt[5];
    var width = 1024, height = Math.max(1, Math.round(width * (y1 - y0) / (x1 - x0)));
    var canvas = document.createElement('canvas');
    canvas.width = width;
    canvas.height = height;
    var ctx = canvas.getContext('2d');
    var p = geometry.positions || [], f = geometry.faces || [];
    var light = [-0.5, 0.5, Math.SQRT1_2];
    var px = function (v) { return (p[3 * v] / scale - x0) / (x1 - x0) * width; };
    var py = function (v) { return (y1 - p[3 * v + 1] / scale) / (y1 - y0) * height; };
    for (var t = 0; t + 2 < f.length; t += 3) {
      var a = f[t], b = f[t + 1], c = f[t + 2];
      var ux = p[3 * b] - p[3 * a], uy = p[3 * b + 1] - p[3 * a + 1], uz = p[3 * b + 2] - p[3 * a + 2];
      var vx = p[3 * c] - p[3 * a], vy = p[3 * c + 1] - p[3 * a + 1], vz = p[3 * c + 2] - p[3 * a + 2];
      var nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
      var n = Math.sqrt(nx * nx + ny * ny + nz * nz) || 1;
      if (nz < 0) n = -n;
      var shade = Math.max(0, (nx * light[0] + ny * light[1] + nz * light[2]) / n);
      var g = Math.round(70 + 175 * shade);
      ctx.fillStyle = 'rgb(' + g + ',' + g + ',' + g + ')';
      ctx.strokeStyle = ctx.fillStyle;
      ctx.beginPath();
      ctx.moveTo(px(a), py(a));
      ctx.lineTo(px(b), py(b));
      ctx.lineTo(px(c), py(c));
      ctx.closePath();
      ctx.fill();
      ctx.stroke();
    }
    var bounds = [[y0, x0], [y1, x1]];
    if (state.hillshade) map.removeLayer(state.hillshade);
    state.hillshade = L.imageOverlay(canvas.toDataURL('image/png'), bounds).addTo(map);
    map.fitBounds(bounds);
  }

  // --- isochrones from the start, the route to the goal
  function drawIsochrones() {
    var values = levels();
    legend.update(values);
    var body = {product: 'GIS_PRODUCT_ISOCHRONES', sources: [mapPoint(state.from)],
                levels: values, nativeCrs: true, options: speedOptions()};
    say('Computing isochrones...');
    return api('POST', meshPath(':exportGis'), body).then(function (blob) {
      return blob.text();
    }).then(function (text) {
      var data = JSON.parse(text);
      // Largest first, so the smaller ones stay clickable on top.
      data.features.sort(function (a, b) { return b.properties.level - a.properties.level; });
      var layer = geoJsonLayer(data, 'geodex-isochrone', function (feature) {
        var k = values.indexOf(feature.properties.level);
        var color = colors[(k < 0 ? 0 : k) % colors.length];
        return {color: color, weight: 1.5, fillColor: color, fillOpacity: 0.25};
      }).addTo(map);
      state.layers.push(layer);
      offerDownload('isochrones (GeoJSON)', new Blob([text], {type: 'application/geo+json'}),
                    'isochrones.geojson');
      say('Click a goal for the route.');
    });
  }

  function drawRoute() {
    var body = {product: 'GIS_PRODUCT_PATH', sources: [mapPoint(state.from)],
                points: [mapPoint(state.to)], nativeCrs: true, options: speedOptions()};
    say('Computing the route...');
    return api('POST', meshPath(':exportGis'), body).then(function (blob) {
      return blob.text();
    }).then(function (text) {
      var data = JSON.parse(text);
      var layer = geoJsonLayer(data, 'geodex-route', function () {
        return {color: '#1f3fbf', weight: 4, opacity: 0.9};
      }).addTo(map);
      state.layers.push(layer);
      var props = data.features[0].properties;
      var lengthText = props.length_m.toFixed(1) + ' m';
      if (props.time_s !== undefined) lengthText += ', ' + (props.time_s / 60).toFixed(1) + ' min';
      resultEl.textContent = 'Route: ' + lengthText;
      offerDownload('route (GeoJSON)', new Blob([text], {type: 'application/geo+json'}),
                    'route.geojson');
      say('Click the map for a new start.');
    });
  }

  function offerRaster() {
    var link = document.createElement('a');
    link.href = '#';
    link.textContent = 'distance raster (GeoTIFF)';
    link.onclick = function (event) {
      event.preventDefault();
      var body = {product: 'GIS_PRODUCT_DISTANCE_RASTER', sources: [mapPoint(state.from)],
                  options: speedOptions()};
      api('POST', meshPath(':exportGis'), body).then(function (blob) {
        link.remove();
        offerDownload('distance raster (GeoTIFF): save', blob, 'distance.tif');
      }).catch(function (e) { say(e.message, true); });
    };
    downloadsEl.appendChild(link);
    downloadsEl.appendChild(document.createElement('br'));
  }

  function marker(latlng, label) {
    var m = L.circleMarker(latlng, {radius: 6, color: '#000', weight: 2, fillColor: '#fff',
                                    fillOpacity: 1}).bindTooltip(label).addTo(map);
    state.layers.push(m);
  }

  function setStart(latlng) {
    clearLayers();
    state.from = latlng;
    state.to = null;
    marker(latlng, 'start');
    updateLink();
    return drawIsochrones().then(offerRaster);
  }

  function setGoal(latlng) {
    state.to = latlng;
    marker(latlng, 'goal');
    updateLink();
    return drawRoute();
  }

  map.on('click', function (event) {
    if (!state.terrain) return;
    var done = state.from && !state.to ? setGoal(event.latlng) : setStart(event.latlng);
    done.catch(function (e) { say(e.message, true); });
  });
  speedSelect.onchange = levelsInput.onchange = function () {
    updateLink();
    if (state.from) {
      var goal = state.to;
      setStart(state.from).then(function () { if (goal) return setGoal(goal); })
          .catch(function (e) { say(e.message, true); });
    }
  };

  function parsePoint(text) {
    var xy = (text || '').split(',').map(parseFloat);
    return xy.length === 2 && isFinite(xy[0]) && isFinite(xy[1]) ? L.latLng(xy[1], xy[0]) : null;
  }

  function openMesh(name) {
    state.mesh = name;
    clearLayers();
    say('Loading ' + name + '...');
    return api('GET', meshPath()).then(function (mesh) {
      state.terrain = mesh.terrain;
      return api('POST', meshPath(':getMeshGeometry'), {});
    }).then(function (geometry) {
      drawHillshade(geometry, state.terrain);
      say('Click the map: a start (isochrones), then a goal (the route).');
      updateLink();
    });
  }

  // --- start: the DEMs (meshes with a projected map), the deep link
  if (params.get('levels')) levelsInput.value = params.get('levels');
  var speed = params.get('speed');
  if (speed) {
    if (!Array.prototype.some.call(speedSelect.options, function (o) { return o.value === speed; })) {
      var option = document.createElement('option');
      option.value = speed;
      option.textContent = speed;
      speedSelect.appendChild(option);
    }
    speedSelect.value = speed;
  }
  api('GET', '/v1/meshes?pageSize=1000').then(function (list) {
    var dems = (list.meshes || []).filter(function (m) {
      return m.terrain && !m.terrain.reprojected;
    });
    if (dems.length === 0) throw new Error('No DEM on this server: upload a GeoTIFF (POST /v1/meshes).');
    var wanted = params.get('mesh');
    var chosen = null;
    dems.forEach(function (m) {
      var id = m.name.replace(/^meshes\//, '');
      var option = document.createElement('option');
      option.value = m.displayName || id;
      option.textContent = (m.displayName || id.slice(0, 12)) + ' (' + m.terrain.gridWidth + ' x ' +
                           m.terrain.gridHeight + ')';
      meshSelect.appendChild(option);
      if (wanted && (wanted === id || wanted === m.displayName)) chosen = option.value;
    });
    meshSelect.value = chosen || meshSelect.options[0].value;
    meshSelect.onchange = function () {
      state.from = state.to = null;
      openMesh(meshSelect.value).catch(function (e) { say(e.message, true); });
    };
    return openMesh(meshSelect.value);
  }).then(function () {
    var from = parsePoint(params.get('from')), to = parsePoint(params.get('to'));
    if (!from) return;
    return setStart(from).then(function () { if (to) return setGoal(to); });
  }).catch(function (e) { say(e.message, true); });
})();
