// The `tcb view` page. It plays the joint positions that `tcb` sampled
// with the runtime (the JSON in #tcb-data) on a ground grid, with three.js
// (the global THREE), and shows the picked joint's curves: the SVG that
// `tcb plot` draws. It computes no animation: at a frame's time a joint is
// where the runtime put it (and a leaf joint's tip turned as the runtime
// turned it); between frames it is interpolated linearly.
// window.tcbView lets a test read what the page shows.
(function () {
  "use strict";
  const data = JSON.parse(document.getElementById("tcb-data").textContent);
  const $ = (id) => document.getElementById(id);
  const times = data.times;
  const frames = times.length;
  const start = times[0];
  const end = times[frames - 1];
  const figure = data.figure;
  const joints = figure ? figure.names.length : 0;
  const positions = figure ? Float32Array.from(figure.positions) : new Float32Array(0);

  let time = start;
  let playing = false;
  let speed = 1;
  let picked = null;

  // ---- header
  document.title = `${data.title}: tcb view`;
  $("title").textContent = data.title;
  $("summary").textContent = [
    figure ? `${joints} joints` : "no skeleton: the tracks' curves alone",
    `${frames} frames at ${+data.fps.toFixed(3)} fps (${data.rate})`,
    `${+start.toFixed(4)} to ${+end.toFixed(4)} s`,
    `tcb ${data.version}`,
  ].join(" · ");

  // ---- time
  /** The frame at or before `t`, and how far `t` is toward the next one (0 to 1). */
  function frameAt(t) {
    let lo = 0;
    let hi = frames - 1;
    if (t <= times[0]) return [0, 0];
    if (t >= times[hi]) return [hi, 0];
    while (hi - lo > 1) {
      const mid = (lo + hi) >> 1;
      if (times[mid] <= t) lo = mid;
      else hi = mid;
    }
    return [lo, (t - times[lo]) / (times[lo + 1] - times[lo])];
  }

  // ---- the scene (a clip with a skeleton only)
  let view = null;
  if (figure) view = makeView();
  else document.body.classList.add("no-skeleton");

  function makeView() {
    const up = figure.up;
    // Model space to three's Y-up world: a Z-up rig turns -90 degrees about X.
    const world = (x, y, z) => (up === 2 ? [x, z, -y] : [x, y, z]);
    const rootJoint = Math.max(0, figure.parents.indexOf(null));
    // Extent of the motion, in world space.
    const lo = [Infinity, Infinity, Infinity];
    const hi = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < positions.length; i += 3) {
      const p = world(positions[i], positions[i + 1], positions[i + 2]);
      for (let k = 0; k < 3; k++) {
        lo[k] = Math.min(lo[k], p[k]);
        hi[k] = Math.max(hi[k], p[k]);
      }
    }
    // The figure's height: the first frame's extent along up.
    let fLo = Infinity;
    let fHi = -Infinity;
    for (let j = 0; j < joints; j++) {
      const p = world(positions[3 * j], positions[3 * j + 1], positions[3 * j + 2]);
      fLo = Math.min(fLo, p[1]);
      fHi = Math.max(fHi, p[1]);
    }
    const span = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
    const height = fHi - fLo > 1e-6 ? fHi - fLo : span > 1e-6 ? span : 1;
    const ground = lo[1];

    const canvas = $("view");
    const renderer = new THREE.WebGLRenderer({ canvas, antialias: true });
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    renderer.shadowMap.enabled = true;
    renderer.shadowMap.type = THREE.PCFSoftShadowMap;
    const scene = new THREE.Scene();
    scene.background = new THREE.Color(0xf3f4f7);
    scene.add(new THREE.HemisphereLight(0xffffff, 0x8a8f99, 2.2));
    const sun = new THREE.DirectionalLight(0xffffff, 1.6);
    scene.add(sun, sun.target);

    // Ground: a grid of round steps about a quarter of the figure's
    // height, covering the motion with a margin, and a plane that takes
    // the figure's shadow.
    const nice = (x) => {
      const p = 10 ** Math.floor(Math.log10(x));
      return [1, 2, 5, 10].map((m) => m * p).find((s) => s >= x * 0.999);
    };
    const cell = nice(height / 4);
    const cx = Math.round((lo[0] + hi[0]) / 2 / cell) * cell;
    const cz = Math.round((lo[2] + hi[2]) / 2 / cell) * cell;
    const reach = Math.max(hi[0] - lo[0], hi[2] - lo[2]) / 2 + 2 * height;
    const divisions = 2 * Math.ceil(reach / cell);
    const size = divisions * cell;
    const grid = new THREE.GridHelper(size, divisions, 0x9aa1ad, 0xcdd1d8);
    grid.position.set(cx, ground, cz);
    scene.add(grid);
    const floor = new THREE.Mesh(
      new THREE.PlaneGeometry(size, size),
      new THREE.ShadowMaterial({ color: 0x20242c, opacity: 0.22 }),
    );
    floor.rotation.x = -Math.PI / 2;
    floor.position.set(cx, ground + 1e-3 * height, cz);
    floor.receiveShadow = true;
    scene.add(floor);
    sun.position.set(cx + 0.6 * size, ground + 1.5 * size, cz + 0.4 * size);
    sun.target.position.set(cx, ground, cz);
    sun.castShadow = true;
    sun.shadow.mapSize.set(2048, 2048);
    Object.assign(sun.shadow.camera, {
      left: -size / 2,
      right: size / 2,
      top: size / 2,
      bottom: -size / 2,
      near: 0.1 * size,
      far: 4 * size,
    });
    sun.shadow.camera.updateProjectionMatrix();

    // The root's path on the ground.
    const trail = [];
    for (let f = 0; f < frames; f++) {
      const o = 3 * (f * joints + rootJoint);
      const p = world(positions[o], positions[o + 1], positions[o + 2]);
      trail.push(p[0], ground + 2e-3 * height, p[2]);
    }
    const path = new THREE.Line(
      new THREE.BufferGeometry().setAttribute("position", new THREE.Float32BufferAttribute(trail, 3)),
      new THREE.LineBasicMaterial({ color: 0x4a6fb5 }),
    );
    scene.add(path);

    // The figure: model space inside a group that turns it Y-up.
    const body = new THREE.Group();
    if (up === 2) body.rotation.x = -Math.PI / 2;
    scene.add(body);
    const boneMaterial = new THREE.MeshLambertMaterial({ color: 0xd04020 });
    const jointMaterial = new THREE.MeshLambertMaterial({ color: 0x23395d });
    const pickedMaterial = new THREE.MeshLambertMaterial({ color: 0xf2b600 });
    const sphere = new THREE.SphereGeometry(0.022 * height, 16, 12);
    const cylinder = new THREE.CylinderGeometry(0.013 * height, 0.013 * height, 1, 10);
    const spheres = figure.names.map((name, j) => {
      const m = new THREE.Mesh(sphere, jointMaterial);
      m.name = name;
      m.userData.joint = j;
      m.castShadow = true;
      body.add(m);
      return m;
    });
    const bones = figure.parents.map((parent, j) => {
      if (parent === null) return null;
      const m = new THREE.Mesh(cylinder, boneMaterial);
      m.userData.joint = j;
      m.castShadow = true;
      body.add(m);
      return m;
    });

    // A leaf joint's rotation moves no joint: it gets a tip along its +Y
    // (glTF's bone axis), about half as long as its bone.
    const tipRotations = Float32Array.from(figure.tip_rotations);
    const cone = new THREE.CylinderGeometry(0, 0.03 * height, 1, 12);
    cone.translate(0, 0.5, 0);
    const tips = figure.tips.map((j) => {
      const p = figure.parents[j];
      let length = 0;
      if (p !== null) {
        const d = [0, 1, 2].map((k) => positions[3 * j + k] - positions[3 * p + k]);
        length = 0.6 * Math.hypot(...d);
      }
      const m = new THREE.Mesh(cone, boneMaterial);
      m.scale.set(1, length > 1e-6 * height ? length : 0.12 * height, 1);
      m.userData.joint = j;
      m.castShadow = true;
      body.add(m);
      return m;
    });

    // The camera: from the side of the root's travel (so that moving
    // forward shows as moving across), a little above, taking in the whole
    // motion.
    const first = world(...positions.slice(3 * rootJoint, 3 * rootJoint + 3));
    const lastO = 3 * ((frames - 1) * joints + rootJoint);
    const last = world(...positions.slice(lastO, lastO + 3));
    let dx = last[0] - first[0];
    let dz = last[2] - first[2];
    if (Math.hypot(dx, dz) < 0.2 * height) [dx, dz] = [1, 0];
    const len = Math.hypot(dx, dz);
    const along = [dx / len, dz / len];
    const side = [-along[1], along[0]];
    const extentAlong = Math.abs(along[0]) * (hi[0] - lo[0]) + Math.abs(along[1]) * (hi[2] - lo[2]);
    const extentSide = Math.abs(side[0]) * (hi[0] - lo[0]) + Math.abs(side[1]) * (hi[2] - lo[2]);
    const camera = new THREE.PerspectiveCamera(35, 1, 0.01 * height, 200 * (span + height));
    const controls = new THREE.OrbitControls(camera, canvas);
    const target = new THREE.Vector3((lo[0] + hi[0]) / 2, ground + 0.45 * height, (lo[2] + hi[2]) / 2);

    function frameCamera() {
      const aspect = camera.aspect;
      const tanV = Math.tan((camera.fov * Math.PI) / 360);
      const tanH = tanV * aspect;
      const dist =
        1.15 * Math.max((extentAlong / 2 + 0.3 * height) / tanH, (hi[1] - ground + 0.3 * height) / 2 / tanV) +
        extentSide / 2;
      camera.position.set(target.x + side[0] * dist, target.y + 0.3 * dist, target.z + side[1] * dist);
      controls.target.copy(target);
      controls.update();
    }

    function resize() {
      const w = canvas.clientWidth;
      const h = canvas.clientHeight;
      if (w === 0 || h === 0) return;
      renderer.setSize(w, h, false);
      camera.aspect = w / h;
      camera.updateProjectionMatrix();
    }
    resize();
    frameCamera();

    const current = new Float32Array(3 * joints);
    const axis = new THREE.Vector3(0, 1, 0);
    const a = new THREE.Vector3();
    const b = new THREE.Vector3();
    let followFrom = null;

    /** Puts the figure at time `t`. */
    function pose(t) {
      const [f, w] = frameAt(t);
      const o = 3 * f * joints;
      if (w === 0) current.set(positions.subarray(o, o + 3 * joints));
      else {
        const n = o + 3 * joints;
        for (let i = 0; i < 3 * joints; i++) current[i] = positions[o + i] + w * (positions[n + i] - positions[o + i]);
      }
      for (let j = 0; j < joints; j++) spheres[j].position.set(current[3 * j], current[3 * j + 1], current[3 * j + 2]);
      for (let j = 0; j < joints; j++) {
        const bone = bones[j];
        if (!bone) continue;
        const p = figure.parents[j];
        a.set(current[3 * p], current[3 * p + 1], current[3 * p + 2]);
        b.set(current[3 * j], current[3 * j + 1], current[3 * j + 2]);
        const length = a.distanceTo(b);
        bone.visible = length > 1e-9;
        if (!bone.visible) continue;
        bone.position.copy(a).add(b).multiplyScalar(0.5);
        bone.quaternion.setFromUnitVectors(axis, b.sub(a).divideScalar(length));
        bone.scale.set(1, length, 1);
      }
      const k = tips.length;
      for (let i = 0; i < k; i++) {
        const o = 4 * (f * k + i);
        let q = tipRotations.subarray(o, o + 4);
        if (w > 0) {
          // nlerp on the nearer hemisphere.
          const n = tipRotations.subarray(o + 4 * k, o + 8 * k);
          const s = q[0] * n[0] + q[1] * n[1] + q[2] * n[2] + q[3] * n[3] < 0 ? -1 : 1;
          q = q.map((c, at) => c + w * (s * n[at] - c));
        }
        const tip = tips[i];
        tip.quaternion.set(q[0], q[1], q[2], q[3]).normalize();
        tip.position.copy(spheres[figure.tips[i]].position);
      }
      if ($("follow").checked) {
        const r = spheres[rootJoint].getWorldPosition(new THREE.Vector3());
        if (followFrom) {
          const d = r.clone().sub(followFrom).setY(0);
          camera.position.add(d);
          controls.target.add(d);
          controls.update();
        }
        followFrom = r;
      } else followFrom = null;
    }

    function render() {
      renderer.render(scene, camera);
    }

    function pick(name) {
      for (const s of spheres) s.material = s.name === name ? pickedMaterial : jointMaterial;
    }

    // Click (not drag) on a joint or a bone: plot that joint.
    const raycaster = new THREE.Raycaster();
    let down = null;
    canvas.addEventListener("pointerdown", (e) => (down = [e.clientX, e.clientY]));
    canvas.addEventListener("pointerup", (e) => {
      if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;
      const r = canvas.getBoundingClientRect();
      const ndc = new THREE.Vector2(((e.clientX - r.left) / r.width) * 2 - 1, 1 - ((e.clientY - r.top) / r.height) * 2);
      raycaster.setFromCamera(ndc, camera);
      const hit = raycaster.intersectObjects([...spheres, ...bones.filter(Boolean), ...tips], false)[0];
      if (hit) choose(figure.names[hit.object.userData.joint]);
    });
    controls.addEventListener("change", () => requestDraw());
    new ResizeObserver(() => {
      resize();
      requestDraw();
    }).observe(canvas);

    /** A model-space point of joint `name` at the current time, in canvas pixels. */
    function project(name) {
      const s = spheres[figure.names.indexOf(name)];
      const v = s.getWorldPosition(new THREE.Vector3()).project(camera);
      return { x: ((v.x + 1) / 2) * canvas.clientWidth, y: ((1 - v.y) / 2) * canvas.clientHeight };
    }

    return {
      pose,
      render,
      pick,
      project,
      root: figure.names[rootJoint],
      jointPositions: () => Object.fromEntries(spheres.map((s) => [s.name, s.position.toArray()])),
      ground,
      height,
    };
  }

  // ---- curves
  const select = $("joint");
  data.groups.forEach((g, i) => select.add(new Option(g.name, String(i))));
  if (figure) {
    // Joints no track animates (BVH End Sites) can be picked in the scene.
    const named = new Set(data.groups.map((g) => g.name));
    for (const n of figure.names) if (!named.has(n)) select.add(new Option(`${n} (not animated)`, `joint:${n}`));
  }
  const img = $("plot-img");
  const cursor = $("cursor");
  let plot = null; // { group, x0, x1, width }
  let url = null;

  /** The curves of `name` (a joint or a group of tracks). */
  function choose(name) {
    picked = name;
    const i = data.groups.findIndex((g) => g.name === name);
    select.value = i >= 0 ? String(i) : `joint:${name}`;
    if (view) view.pick(name);
    if (url) URL.revokeObjectURL(url);
    url = null;
    plot = null;
    if (i < 0) {
      img.removeAttribute("src");
      $("caption").textContent = `No track animates ${name}: it follows its parent.`;
    } else {
      const g = data.groups[i];
      // An <img>, not inline markup: the SVG's text comes from the clip file.
      url = URL.createObjectURL(new Blob([g.svg], { type: "image/svg+xml" }));
      img.src = url;
      img.alt = `curves of ${g.tracks.join(", ")}`;
      $("caption").textContent = `${g.tracks.join(", ")}: tcb plot ${data.title} ${g.tracks
        .map((t) => `--track ${t}`)
        .join(" ")} --from ${+g.from.toFixed(6)} --to ${+g.to.toFixed(6)}`;
      plot = { group: g, ...timeAxis(g.svg) };
    }
    requestDraw();
  }

  /** Where the plot's time axis runs, in SVG pixels: the curves span it,
   * sampled from its start to its end, so the widest polyline shows it. */
  function timeAxis(svg) {
    const doc = new DOMParser().parseFromString(svg, "image/svg+xml");
    const width = Number(doc.documentElement.getAttribute("width")) || 1;
    let x0 = 0;
    let x1 = 0;
    for (const line of doc.querySelectorAll("polyline")) {
      const xs = (line.getAttribute("points") || "")
        .trim()
        .split(/\s+/)
        .map((p) => Number(p.split(",")[0]))
        .filter(Number.isFinite);
      if (xs.length < 2) continue;
      const lo = xs.reduce((m, x) => Math.min(m, x), Infinity);
      const hi = xs.reduce((m, x) => Math.max(m, x), -Infinity);
      if (hi - lo > x1 - x0) [x0, x1] = [lo, hi];
    }
    return { x0, x1, width };
  }

  select.addEventListener("change", () => {
    const v = select.value;
    choose(v.startsWith("joint:") ? v.slice(6) : data.groups[Number(v)].name);
  });

  // ---- controls
  const timeline = $("timeline");
  timeline.max = String(frames - 1);
  const playButton = $("play");
  function setPlaying(p) {
    playing = p && frames > 1;
    playButton.textContent = playing ? "Pause" : "Play";
    last = null;
    requestDraw();
  }
  playButton.addEventListener("click", () => setPlaying(!playing));
  timeline.addEventListener("input", () => {
    setPlaying(false);
    time = times[Number(timeline.value)];
    requestDraw();
  });
  $("speed").addEventListener("change", (e) => (speed = Number(e.target.value)));
  $("follow").addEventListener("change", () => requestDraw());
  document.addEventListener("keydown", (e) => {
    if (e.target instanceof HTMLSelectElement || e.target instanceof HTMLInputElement) return;
    if (e.key === " ") {
      e.preventDefault();
      setPlaying(!playing);
    } else if (e.key === "ArrowRight" || e.key === "ArrowLeft") {
      const [f] = frameAt(time);
      const n = Math.min(frames - 1, Math.max(0, f + (e.key === "ArrowRight" ? 1 : -1)));
      setPlaying(false);
      time = times[n];
      requestDraw();
    }
  });

  // ---- drawing: on request, and every animation frame while playing
  let queued = false;
  let last = null;
  function requestDraw() {
    if (!queued) {
      queued = true;
      requestAnimationFrame(tick);
    }
  }
  function tick(now) {
    queued = false;
    if (playing) {
      if (last !== null) {
        time += ((now - last) / 1000) * speed;
        if (time > end) time = start + ((time - start) % (end - start || 1));
      }
      last = now;
      requestDraw();
    }
    draw();
  }
  function draw() {
    const [f, w] = frameAt(time);
    if (document.activeElement !== timeline || playing) timeline.value = String(w > 0.5 ? Math.min(f + 1, frames - 1) : f);
    $("time").textContent = `${time.toFixed(3)} s`;
    if (plot && plot.x1 > plot.x0) {
      const g = plot.group;
      const x = plot.x0 + ((time - g.from) / (g.to - g.from)) * (plot.x1 - plot.x0);
      cursor.style.left = `${(100 * x) / plot.width}%`;
      cursor.style.display = "block";
    } else cursor.style.display = "none";
    if (view) {
      view.pose(time);
      view.render();
    }
  }

  // ---- start
  // The root's curves first, or the first group's where no track animates the root.
  const rootName = figure ? figure.names[Math.max(0, figure.parents.indexOf(null))] : null;
  const first =
    data.joint ??
    (data.groups.some((g) => g.name === rootName) ? rootName : data.groups.length ? data.groups[0].name : rootName);
  if (first !== null) choose(first);
  draw();

  /** What a test reads (and sets, through the controls). */
  window.tcbView = {
    hasSkeleton: Boolean(figure),
    times,
    groups: data.groups.map((g) => g.name),
    joints: figure ? figure.names : [],
    root: view ? view.root : null,
    /** Time, frame, playback and the plot shown. */
    state: () => ({
      time,
      frame: frameAt(time)[0],
      playing,
      speed,
      picked,
      plot: plot ? plot.group.name : null,
      cursor: cursor.style.display === "none" ? null : cursor.getBoundingClientRect().left - img.getBoundingClientRect().left,
    }),
    /** Each joint's position as drawn (model space), by name. */
    jointPositions: () => (view ? view.jointPositions() : {}),
    /** Where joint `name` is drawn, in canvas pixels. */
    project: (name) => (view ? view.project(name) : null),
    /** Resolves once the next frame is drawn. */
    drawn: () => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))),
  };
  window.tcbView.ready = true;
})();
