//! Exact area of the intersection of a disk and an axis-aligned rectangle.
//!
//! With the disk centred at the origin, radius `R`, and `s(x) = √(R² − x²)`, the area of the
//! disk inside the quadrant `{x ≤ a, y ≤ b}` is
//! `F(a, b) = ∫_{−R}^{a} max(0, min(b, s(x)) + s(x)) dx`,
//! evaluated in closed form with `H(x) = ∫_0^x s = (x s(x) + R² asin(x/R)) / 2`.
//! The area inside `[x₀, x₁] × [y₀, y₁]` is then the inclusion–exclusion
//! `F(x₁, y₁) − F(x₀, y₁) − F(x₁, y₀) + F(x₀, y₀)`.

use dem::math::Vector;

/// `H(x) = ∫_0^x √(R² − u²) du` for `|x| ≤ R`.
fn h(x: f64, r: f64) -> f64 {
    let x = x.clamp(-r, r);
    let s = (r * r - x * x).max(0.0).sqrt();
    0.5 * (x * s + r * r * (x / r).clamp(-1.0, 1.0).asin())
}

/// Area of the disk of radius `r` centred at the origin inside `{x ≤ a, y ≤ b}`.
fn quadrant_area(a: f64, b: f64, r: f64) -> f64 {
    if a <= -r || b <= -r {
        return 0.0;
    }
    let a = a.min(r);
    if b >= r {
        // full vertical chords: ∫_{−R}^{a} 2 s
        return 2.0 * (h(a, r) - h(-r, r));
    }
    // half-width of the chord at height |b|
    let c = (r * r - b * b).max(0.0).sqrt();
    let x2 = a.clamp(-c, c);
    // central part |x| < c: chord from −s to b, length b + s
    let central = b * (x2 + c) + h(x2, r) - h(-c, r);
    if b >= 0.0 {
        // outer parts |x| ≥ c: whole chords 2 s
        let x1 = a.clamp(-r, -c);
        let x3 = a.clamp(c, r);
        central + 2.0 * (h(x1, r) - h(-r, r)) + 2.0 * (h(x3, r) - h(c, r))
    } else {
        central
    }
}

/// Exact area (m²) of the disk of centre `centre` and radius `radius` inside the rectangle
/// `[min.x, max.x] × [min.y, max.y]`. Returns 0 for an empty rectangle or a non-positive radius.
pub fn disk_rectangle_area(centre: &Vector, radius: f64, min: &Vector, max: &Vector) -> f64 {
    if radius <= 0.0 || max.x <= min.x || max.y <= min.y {
        return 0.0;
    }
    let (x0, x1) = (min.x - centre.x, max.x - centre.x);
    let (y0, y1) = (min.y - centre.y, max.y - centre.y);
    let r = radius;
    if x0 <= -r && x1 >= r && y0 <= -r && y1 >= r {
        return std::f64::consts::PI * r * r;
    }
    let area = quadrant_area(x1, y1, r) - quadrant_area(x0, y1, r) - quadrant_area(x1, y0, r)
        + quadrant_area(x0, y0, r);
    area.clamp(0.0, std::f64::consts::PI * r * r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn half_and_quarter_disks() {
        let c = Vector::new(0.2, -0.1);
        let r = 0.5;
        let big = 10.0;
        let half = disk_rectangle_area(&c, r, &Vector::new(c.x, -big), &Vector::new(big, big));
        assert!((half - PI * r * r / 2.0).abs() < 1e-14);
        let lower_half =
            disk_rectangle_area(&c, r, &Vector::new(-big, -big), &Vector::new(big, c.y));
        assert!((lower_half - PI * r * r / 2.0).abs() < 1e-14);
        let quarter = disk_rectangle_area(&c, r, &c, &Vector::new(big, big));
        assert!((quarter - PI * r * r / 4.0).abs() < 1e-14);
        let none = disk_rectangle_area(&c, r, &Vector::new(1.0, 1.0), &Vector::new(2.0, 2.0));
        assert_eq!(none, 0.0);
    }

    #[test]
    fn circular_segment() {
        // segment of height r − d cut by the line x = d: area r² acos(d/r) − d √(r² − d²)
        let r = 1.3;
        for &d in &[-0.9, -0.2, 0.0, 0.4, 1.1] {
            let seg = disk_rectangle_area(
                &Vector::zeros(),
                r,
                &Vector::new(d, -5.0),
                &Vector::new(5.0, 5.0),
            );
            let exact = r * r * (d / r).acos() - d * (r * r - d * d).sqrt();
            assert!((seg - exact).abs() < 1e-13, "d = {d}: {seg} vs {exact}");
        }
    }

    #[test]
    fn tiling_sums_to_the_disk() {
        // a 7 × 5 irregular grid of rectangles covering the disk: areas add up to π r²
        let c = Vector::new(0.13, 0.71);
        let r = 0.37;
        let xs = [-1.0, -0.1, 0.05, 0.1, 0.22, 0.3, 0.49, 2.0];
        let ys = [-1.0, 0.4, 0.6, 0.75, 0.9, 3.0];
        let mut total = 0.0;
        for i in 0..xs.len() - 1 {
            for j in 0..ys.len() - 1 {
                total += disk_rectangle_area(
                    &c,
                    r,
                    &Vector::new(xs[i], ys[j]),
                    &Vector::new(xs[i + 1], ys[j + 1]),
                );
            }
        }
        assert!((total - PI * r * r).abs() < 1e-14, "{total}");
    }

    #[test]
    fn matches_a_fine_quadrature() {
        // midpoint rule on a 4000 × 4000 grid over the disk's box: error O(r²/N^1.5)
        let c = Vector::new(0.0, 0.0);
        let r = 1.0;
        let (min, max) = (Vector::new(-0.3, -2.0), Vector::new(0.8, 0.45));
        let exact = disk_rectangle_area(&c, r, &min, &max);
        let n = 4000;
        let dx = 2.0 * r / n as f64;
        let mut count = 0u64;
        for i in 0..n {
            let x = -r + (i as f64 + 0.5) * dx;
            for k in 0..n {
                let y = -r + (k as f64 + 0.5) * dx;
                if x * x + y * y <= r * r && x >= min.x && x <= max.x && y >= min.y && y <= max.y {
                    count += 1;
                }
            }
        }
        let quad = count as f64 * dx * dx;
        assert!((quad - exact).abs() < 2e-5, "{quad} vs {exact}");
    }
}
