// The floor plane of the feet step in the 3D views: a translucent quad at the floor's height,
// perpendicular to the up axis the step found (or the plane it fitted to a tilted floor), in
// each view's scene (scene3d.js). Its corners come from scene-data.js: floorPlane.
import * as THREE from "/static/vendor/three/three.module.min.js";

const FLOOR = new THREE.Color("#27ae60");
const FLOOR_OPACITY = 0.18;

/** The floor's mesh of one view: empty and hidden until setFloorPlane gives it corners. Added
 * last to `scene`: drawn after the opaque parts (the renderer does not sort objects). */
export function floorMesh(scene) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute("position", new THREE.BufferAttribute(new Float32Array(12), 3));
  geometry.setIndex([0, 1, 2, 0, 2, 3]);
  const material = new THREE.MeshBasicMaterial({
    color: FLOOR, transparent: true, opacity: FLOOR_OPACITY, side: THREE.DoubleSide, depthWrite: false,
    // Drawn just behind the grid lying at the same height.
    polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
  });
  const mesh = new THREE.Mesh(geometry, material);
  mesh.visible = false;
  mesh.frustumCulled = false;
  scene.add(mesh);
  return mesh;
}

/** Give `mesh` the corners of `plane` (floorPlane), or hide it for null. */
function setFloorPlane(mesh, plane) {
  if (!plane) { mesh.visible = false; return; }
  const position = mesh.geometry.attributes.position;
  position.array.set(plane.positions);
  position.needsUpdate = true;
  mesh.geometry.setIndex(plane.index);
}

/** Show the floor plane in every view of `v` (the views' state) when there is one and `on`. */
function showFloor(v, on) {
  v.floorOn = on;
  for (const view of Object.values(v.views)) view.floor.visible = Boolean(v.floorPlane) && on;
  v.requestRender();
}

/** The 3D views' floor methods (scene3d.js: viewsApi); `v` is the views' state. */
export function floorControls(v) {
  return {
    /** The feet step's floor plane (scene-data.js: floorPlane; null: none) in every view. */
    setFloor(plane) {
      v.floorPlane = plane;
      for (const view of Object.values(v.views)) setFloorPlane(view.floor, plane);
      showFloor(v, v.floorOn);
    },
    /** Show or hide the floor plane (shown by default when there is one). */
    setFloorShown(on) { showFloor(v, on); },
    /** The floor plane: its up axis, level, whether it is the tilted plane, its corners and
     * whether each view shows it; null for none. */
    floorDrawn() {
      const p = v.floorPlane;
      return p && { axis: p.axis, level: p.level, tilted: p.tilted, corners: [...p.positions], shown: Object.values(v.views).map((view) => view.floor.visible) };
    },
  };
}
