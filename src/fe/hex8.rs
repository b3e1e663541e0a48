//! The 8-node hexahedron: trilinear shape functions, 2×2×2 Gauss quadrature, isotropic linear
//! elasticity, consistent mass.
//!
//! Two stiffness variants on the same 24 DOFs:
//! - [`ElementKind::Hex8`]: the plain trilinear element. It shear-locks in bending: a pure-bending
//!   field gives parasitic shear strain, and the element is too stiff by roughly a factor
//!   `1 + (G/E)·(ℓ/t)²` (ℓ the element length along the bending span, t the bending depth).
//! - [`ElementKind::Hex8Incompatible`]: the same element enriched with the 9 Wilson incompatible
//!   bending modes (1 − ξ²), (1 − η²), (1 − ζ²) per displacement component, in Taylor, Beresford &
//!   Wilson's form (their strains use the Jacobian at the element centre scaled by det J₀/det J,
//!   so the patch test is passed), statically condensed inside the element. It reproduces pure
//!   bending exactly on parallelepipeds and removes the shear locking. Same mass matrix.
//!
//! Local node order: (ξ, η, ζ) = (−,−,−), (+,−,−), (+,+,−), (−,+,−), then the same at ζ = +1.
//! Element DOF 3·a + c is displacement component c (x, y, z) of local node a.
use nalgebra::{Matrix3, SMatrix, Vector3};

/// Corner signs of the 8 local nodes.
pub const CORNERS: [[f64; 3]; 8] =
    [[-1.0, -1.0, -1.0], [1.0, -1.0, -1.0], [1.0, 1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0], [1.0, -1.0, 1.0], [1.0, 1.0, 1.0], [-1.0, 1.0, 1.0]];

/// Isotropic linear-elastic material, SI units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Young's modulus E [Pa].
    pub young: f64,
    /// Poisson's ratio ν [-], in (−1, 0.5).
    pub poisson: f64,
    /// Density ρ [kg/m³].
    pub density: f64,
}

impl Material {
    /// Ti-6Al-4V: E = 114 GPa, ν = 0.34, ρ = 4430 kg/m³.
    pub const TI6AL4V: Material = Material { young: 114e9, poisson: 0.34, density: 4430.0 };

    /// The 6×6 elasticity matrix, Voigt order (xx, yy, zz, xy, yz, zx), engineering shears.
    pub fn elasticity(&self) -> SMatrix<f64, 6, 6> {
        let (e, nu) = (self.young, self.poisson);
        let lam = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let g = e / (2.0 * (1.0 + nu));
        let mut d = SMatrix::<f64, 6, 6>::zeros();
        for i in 0..3 {
            for j in 0..3 {
                d[(i, j)] = lam;
            }
            d[(i, i)] = lam + 2.0 * g;
            d[(i + 3, i + 3)] = g;
        }
        d
    }
}

impl Default for Material {
    fn default() -> Self {
        Material::TI6AL4V
    }
}

/// Which stiffness formulation the hexahedra use (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum ElementKind {
    /// Plain trilinear hexahedron (locks in bending).
    Hex8,
    /// Trilinear hexahedron with 9 condensed incompatible modes (no shear locking).
    #[default]
    Hex8Incompatible,
}

pub type Mat24 = SMatrix<f64, 24, 24>;

/// Shape functions at (ξ, η, ζ).
fn shape(p: [f64; 3]) -> [f64; 8] {
    let mut n = [0.0; 8];
    for (a, c) in CORNERS.iter().enumerate() {
        n[a] = 0.125 * (1.0 + c[0] * p[0]) * (1.0 + c[1] * p[1]) * (1.0 + c[2] * p[2]);
    }
    n
}

/// ∂N_a/∂ξ_k at p: column a holds the gradient of N_a.
fn shape_grad(p: [f64; 3]) -> SMatrix<f64, 3, 8> {
    let mut g = SMatrix::<f64, 3, 8>::zeros();
    for (a, c) in CORNERS.iter().enumerate() {
        let f = [1.0 + c[0] * p[0], 1.0 + c[1] * p[1], 1.0 + c[2] * p[2]];
        g[(0, a)] = 0.125 * c[0] * f[1] * f[2];
        g[(1, a)] = 0.125 * c[1] * f[0] * f[2];
        g[(2, a)] = 0.125 * c[2] * f[0] * f[1];
    }
    g
}

/// Jacobian J[k][l] = ∂x_l/∂ξ_k.
fn jacobian(gn: &SMatrix<f64, 3, 8>, x: &[[f64; 3]; 8]) -> Matrix3<f64> {
    let mut j = Matrix3::zeros();
    for a in 0..8 {
        for k in 0..3 {
            for l in 0..3 {
                j[(k, l)] += gn[(k, a)] * x[a][l];
            }
        }
    }
    j
}

/// Strain–displacement rows for a field with physical gradient `g` (∂φ/∂x, ∂φ/∂y, ∂φ/∂z),
/// written into columns 3·a .. 3·a+3 of `b`.
fn put_b<const C: usize>(b: &mut SMatrix<f64, 6, C>, a: usize, g: &Vector3<f64>) {
    let c = 3 * a;
    b[(0, c)] = g[0];
    b[(1, c + 1)] = g[1];
    b[(2, c + 2)] = g[2];
    b[(3, c)] = g[1];
    b[(3, c + 1)] = g[0];
    b[(4, c + 1)] = g[2];
    b[(4, c + 2)] = g[1];
    b[(5, c)] = g[2];
    b[(5, c + 2)] = g[0];
}

/// A hexahedron that cannot be integrated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("element Jacobian determinant {det:e} ≤ 0 at a Gauss point: the element is inverted or degenerate")]
pub struct InvertedElement {
    pub det: f64,
}

/// Stiffness and consistent mass of one hexahedron with corner coordinates `x` [m].
pub fn hex8_matrices(x: &[[f64; 3]; 8], mat: &Material, kind: ElementKind) -> Result<(Mat24, Mat24), InvertedElement> {
    let d = mat.elasticity();
    let gp = 1.0 / 3f64.sqrt();
    let mut k_uu = Mat24::zeros();
    let mut k_ua = SMatrix::<f64, 24, 9>::zeros();
    let mut k_aa = SMatrix::<f64, 9, 9>::zeros();
    let mut mass = Mat24::zeros();

    // Centre Jacobian for the incompatible modes.
    let j0 = jacobian(&shape_grad([0.0; 3]), x);
    let det0 = j0.determinant();
    let j0_inv = j0.try_inverse().ok_or(InvertedElement { det: det0 })?;

    for &s0 in &[-gp, gp] {
        for &s1 in &[-gp, gp] {
            for &s2 in &[-gp, gp] {
                let p = [s0, s1, s2];
                let gn = shape_grad(p);
                let j = jacobian(&gn, x);
                let det = j.determinant();
                if !(det > 0.0) {
                    return Err(InvertedElement { det });
                }
                let j_inv = j.try_inverse().ok_or(InvertedElement { det })?;
                let mut b = SMatrix::<f64, 6, 24>::zeros();
                for a in 0..8 {
                    let g = j_inv * Vector3::new(gn[(0, a)], gn[(1, a)], gn[(2, a)]);
                    put_b(&mut b, a, &g);
                }
                let db = d * b;
                k_uu += b.transpose() * db * det;

                if kind == ElementKind::Hex8Incompatible {
                    // Modes P_k = 1 − ξ_k², ∂P_k/∂ξ_l = −2 ξ_k δ_kl; physical gradient through J₀,
                    // scaled by det J₀ / det J (Taylor, Beresford & Wilson 1976).
                    let mut ba = SMatrix::<f64, 6, 9>::zeros();
                    for k in 0..3 {
                        let mut dxi = Vector3::zeros();
                        dxi[k] = -2.0 * p[k];
                        let g = j0_inv * dxi * (det0 / det);
                        put_b(&mut ba, k, &g);
                    }
                    k_ua += db.transpose() * ba * det;
                    k_aa += ba.transpose() * d * ba * det;
                }

                let n = shape(p);
                for a in 0..8 {
                    for bb in a..8 {
                        let m = mat.density * det * (n[a] * n[bb]);
                        for c in 0..3 {
                            mass[(3 * a + c, 3 * bb + c)] += m;
                            if bb != a {
                                mass[(3 * bb + c, 3 * a + c)] += m;
                            }
                        }
                    }
                }
            }
        }
    }
    let k = match kind {
        ElementKind::Hex8 => k_uu,
        ElementKind::Hex8Incompatible => {
            let chol = nalgebra::Cholesky::new(k_aa).ok_or(InvertedElement { det: det0 })?;
            let x_au = chol.solve(&k_ua.transpose());
            k_uu - k_ua * x_au
        }
    };
    // Exact (bitwise) symmetry: BᵀDB and the condensation are symmetric only up to round-off.
    let k = (k + k.transpose()) * 0.5;
    Ok((k, mass))
}

/// Element volume ∫ dV by the same quadrature (exact for parallelepipeds).
pub fn hex8_volume(x: &[[f64; 3]; 8]) -> f64 {
    let gp = 1.0 / 3f64.sqrt();
    let mut v = 0.0;
    for &s0 in &[-gp, gp] {
        for &s1 in &[-gp, gp] {
            for &s2 in &[-gp, gp] {
                v += jacobian(&shape_grad([s0, s1, s2]), x).determinant();
            }
        }
    }
    v
}
