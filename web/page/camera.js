// The viewer's camera: a view direction and up vector turned by a
// trackball (Shoemake's arcball), as fvr's geometry contract names them:
// right r = normalize(d x u0), up u = r x d, so that (r, u, -d) is a
// right-handed frame with -d towards the viewer.

const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const normalize = (a) => scale(a, 1 / Math.hypot(a[0], a[1], a[2]));

// Rodrigues: v turned by `angle` about the unit axis k.
function rotate(v, k, angle) {
  const c = Math.cos(angle);
  const s = Math.sin(angle);
  return add(add(scale(v, c), scale(cross(k, v), s)), scale(k, dot(k, v) * (1 - c)));
}

// A point of the canvas, x and y in [-1, 1] (y up), on the unit sphere:
// inside the circle, lifted onto the hemisphere towards the viewer; outside,
// on its rim (turning about the view axis).
function onSphere(x, y) {
  const r2 = x * x + y * y;
  return r2 <= 1 ? [x, y, Math.sqrt(1 - r2)] : [x / Math.sqrt(r2), y / Math.sqrt(r2), 0];
}

export class Camera {
  constructor(dir, up) {
    this.home = [dir, up];
    this.set(dir, up);
  }

  set(dir, up) {
    this.dir = normalize(dir);
    const right = normalize(cross(this.dir, up));
    this.up = cross(right, this.dir);
  }

  reset() {
    this.set(...this.home);
  }

  get right() {
    return cross(this.dir, this.up);
  }

  // Drag from canvas point (x0, y0) to (x1, y1): the volume turns with the
  // pointer, the arc from one sphere point to the other, so the camera
  // turns the opposite way about the same axis, taken to world coordinates.
  drag(x0, y0, x1, y1) {
    const p = onSphere(x0, y0);
    const q = onSphere(x1, y1);
    const axis = cross(p, q);
    const len = Math.hypot(axis[0], axis[1], axis[2]);
    if (len < 1e-9) return;
    const angle = Math.atan2(len, dot(p, q));
    const k = normalize(add(add(scale(this.right, axis[0]), scale(this.up, axis[1])), scale(this.dir, -axis[2])));
    this.set(rotate(this.dir, k, -angle), rotate(this.up, k, -angle));
  }
}
