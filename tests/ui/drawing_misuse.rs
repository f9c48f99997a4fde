// A `Drawing` item: an unknown shape, a field the shape does not have, a colour that is
// not a string literal, a spring with three points, points of mixed dimension, a
// frame that is not one; a scene whose `up` moves, has the wrong dimension or is zero,
// and a second scene.
#[pfaff::mechanism]
mod drawn {
    static x: Coordinate = Coordinate {};
    static y: Coordinate = Coordinate {};
    static phi: Coordinate = Coordinate {};
    static bar: Body = Body {
        origin: [x, y],
        angle: phi,
        mass: 1.0,
        inertia: 0.1,
    };
    static a: Drawing = Circle { center: [x, y] };
    static b: Drawing = Link { points: [[0.0, 0.0], [x, y]], width: 2.0 };
    static c: Drawing = Disc { center: [x, y], radius: 0.1, color: 3.0 };
    static d: Drawing = Spring { points: [[0.0, 0.0], [x, y], [1.0, 1.0]] };
    static e: Drawing = Outline { points: [[0.0, 0.0], [x, y, 0.0]] };
    static f: Drawing = Marker { points: [[0.0, 0.0]], frame: x };
    static g: Drawing = Scene { up: [x, 1.0] };
    static h: Drawing = Scene { up: [0.0, 0.0, 1.0] };
    static k: Drawing = Scene { up: [0.0, 0.0] };
    static s1: Drawing = Scene { up: [0.0, -1.0] };
    static s2: Drawing = Scene { up: [0.0, 1.0] };
}
fn main() {}
