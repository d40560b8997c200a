//! Blender's procedural textures as Cycles evaluates them: the hash, the Perlin noise and its
//! fractal sum (Noise Texture, fBM), the cell colours of the Voronoi Texture (F1, Euclidean) and
//! the Color Ramp (linear, baked into 256 entries). The add-on's corrosion mask is made of these,
//! so they are reproduced value for value (`fidelity/appearance` renders them with Cycles).

use glam::Vec3;

/// Bob Jenkins' lookup3 `final` mix of three words.
fn finish(mut a: u32, mut b: u32, mut c: u32) -> u32 {
    c ^= b;
    c = c.wrapping_sub(b.rotate_left(14));
    a ^= c;
    a = a.wrapping_sub(c.rotate_left(11));
    b ^= a;
    b = b.wrapping_sub(a.rotate_left(25));
    c ^= b;
    c = c.wrapping_sub(b.rotate_left(16));
    a ^= c;
    a = a.wrapping_sub(c.rotate_left(4));
    b ^= a;
    b = b.wrapping_sub(a.rotate_left(14));
    c ^= b;
    c.wrapping_sub(b.rotate_left(24))
}

/// lookup3's seed for `n` words.
const fn seed(n: u32) -> u32 {
    0xdead_beef_u32.wrapping_add(n << 2).wrapping_add(13)
}

fn hash2(x: u32, y: u32) -> u32 {
    let s = seed(2);
    finish(s.wrapping_add(x), s.wrapping_add(y), s)
}

fn hash3(x: u32, y: u32, z: u32) -> u32 {
    let s = seed(3);
    finish(s.wrapping_add(x), s.wrapping_add(y), s.wrapping_add(z))
}

/// A value in 0..1 for integer `i` of the sequence `salt`: each sheet's, wire's or bar's own.
pub(crate) fn draw(i: i32, salt: u32) -> f32 {
    unit(hash2(i as u32, salt))
}

/// A hash as a float in 0..1.
fn unit(h: u32) -> f32 {
    h as f32 / u32::MAX as f32
}

/// The integer below `x` and the fraction above it, as Cycles' `floorfrac` (truncation, one
/// less for negatives).
fn floor_frac(x: f32) -> (i32, f32) {
    let i = x as i32 - i32::from(x < 0.0);
    (i, x - i as f32)
}

fn fade(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

/// Perlin's gradient for hash `h` at offset (x, y, z).
fn gradient(h: u32, x: f32, y: f32, z: f32) -> f32 {
    let h = h & 15;
    let u = if h < 8 { x } else { y };
    let v = if h < 4 {
        y
    } else if h == 12 || h == 14 {
        x
    } else {
        z
    };
    (if h & 1 != 0 { -u } else { u }) + (if h & 2 != 0 { -v } else { v })
}

/// Signed Perlin noise at `p`, about -1..1 (Cycles' `snoise_3d`).
fn signed_noise(p: Vec3) -> f32 {
    let ((x, fx), (y, fy), (z, fz)) = (floor_frac(p.x), floor_frac(p.y), floor_frac(p.z));
    let g = |i: i32, j: i32, k: i32| {
        let h = hash3((x + i) as u32, (y + j) as u32, (z + k) as u32);
        gradient(h, fx - i as f32, fy - j as f32, fz - k as f32)
    };
    let (u, v, w) = (fade(fx), fade(fy), fade(fz));
    let (u1, v1, w1) = (1.0 - u, 1.0 - v, 1.0 - w);
    let r = w1 * (v1 * (g(0, 0, 0) * u1 + g(1, 0, 0) * u) + v * (g(0, 1, 0) * u1 + g(1, 1, 0) * u))
        + w * (v1 * (g(0, 0, 1) * u1 + g(1, 0, 1) * u) + v * (g(0, 1, 1) * u1 + g(1, 1, 1) * u));
    if r.is_finite() { 0.982 * r } else { 0.0 }
}

/// The Noise Texture's fractal (fBM, normalized, lacunarity 2) at `p` (already scaled): 0..1
/// about 0.5.
pub(crate) fn fbm(p: Vec3, detail: f32, roughness: f32) -> f32 {
    let detail = detail.clamp(0.0, 15.0);
    let roughness = roughness.max(0.0);
    let (mut scale, mut amp, mut max_amp, mut sum) = (1.0, 1.0, 0.0, 0.0);
    for _ in 0..=detail as i32 {
        sum += signed_noise(scale * p) * amp;
        max_amp += amp;
        amp *= roughness;
        scale *= 2.0;
    }
    let rest = detail - detail.floor();
    let value = 0.5 * sum / max_amp + 0.5;
    if rest == 0.0 {
        return value;
    }
    let sum2 = sum + signed_noise(scale * p) * amp;
    let value2 = 0.5 * sum2 / (max_amp + amp) + 0.5;
    value + (value2 - value) * rest
}

/// The offset of the Noise Texture's colour channel `channel` (3 or 4; 0 to 2 offset its
/// distortion) from its value's.
fn channel_offset(channel: f32) -> Vec3 {
    let c = channel.to_bits();
    let o = |k: f32| 100.0 + unit(hash2(c, k.to_bits())) * 100.0;
    Vec3::new(o(0.0), o(1.0), o(2.0))
}

/// The Noise Texture's colour output at `p` (already scaled): the fractal at `p` and at two
/// offsets.
pub(crate) fn fbm_colour(p: Vec3, detail: f32, roughness: f32) -> Vec3 {
    Vec3::new(
        fbm(p, detail, roughness),
        fbm(p + channel_offset(3.0), detail, roughness),
        fbm(p + channel_offset(4.0), detail, roughness),
    )
}

/// The random colour of the integer cell `c`, and the position of its point in it: Cycles'
/// signed-integer PCG 3D hash.
fn cell(c: [i32; 3]) -> Vec3 {
    let mut v = c.map(|x| x.wrapping_mul(1_664_525).wrapping_add(1_013_904_223));
    let stir = |v: &mut [i32; 3]| {
        v[0] = v[0].wrapping_add(v[1].wrapping_mul(v[2]));
        v[1] = v[1].wrapping_add(v[2].wrapping_mul(v[0]));
        v[2] = v[2].wrapping_add(v[0].wrapping_mul(v[1]));
    };
    stir(&mut v);
    v = v.map(|x| x ^ (x >> 16));
    stir(&mut v);
    let [x, y, z] = v.map(|x| (x & 0x7fff_ffff) as f32 * (1.0 / 0x7fff_ffff as f32));
    Vec3::new(x, y, z)
}

/// The Voronoi Texture's colour (F1, Euclidean, randomness 1) at `p` (already scaled): the
/// colour of the cell whose point is nearest.
pub(crate) fn voronoi_colour(p: Vec3) -> Vec3 {
    let base = p.floor();
    let local = p - base;
    let c = [base.x as i32, base.y as i32, base.z as i32];
    // a cell's colour is its point's offset within it: one hash gives both
    let (mut best, mut colour) = (f32::MAX, Vec3::ZERO);
    for k in -1..=1 {
        for j in -1..=1 {
            for i in -1..=1 {
                let hash = cell([c[0] + i, c[1] + j, c[2] + k]);
                let d = (Vec3::new(i as f32, j as f32, k as f32) + hash).distance(local);
                if d < best {
                    best = d;
                    colour = hash;
                }
            }
        }
    }
    colour
}

/// Scene-linear Rec. 709 luminance: how Cycles turns a colour into a float.
pub(crate) fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.212_639, 0.715_169, 0.072_192))
}

/// A grey Color Ramp of linear interpolation: its stops (position, value) in the order they
/// were made, evaluated as Blender's colour band does (which reads unsorted stops as they
/// lie) and baked into 256 entries as Cycles looks it up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Ramp(pub(crate) [(f32, f32); 2]);

impl Ramp {
    /// Blender's colour band at `x`.
    fn band(&self, x: f32) -> f32 {
        let s = &self.0;
        if x <= s[0].0 {
            return s[0].1;
        }
        match s.iter().position(|stop| stop.0 > x) {
            None => s[s.len() - 1].1,
            Some(a) => {
                let (lo, hi) = (s[a], s[a - 1]);
                let t = if hi.0 != lo.0 {
                    (x - lo.0) / (hi.0 - lo.0)
                } else {
                    0.0
                };
                (1.0 - t) * lo.1 + t * hi.1
            }
        }
    }

    /// The ramp at `x`, as Cycles' 256-entry table gives it.
    pub(crate) fn at(&self, x: f32) -> f32 {
        const LAST: f32 = 255.0;
        let f = x.clamp(0.0, 1.0) * LAST;
        let i = f as i32;
        let t = f - i as f32;
        let entry = |i: i32| self.band(i as f32 / LAST);
        if t > 0.0 && i < 255 {
            (1.0 - t) * entry(i) + t * entry(i + 1)
        } else {
            entry(i)
        }
    }
}
