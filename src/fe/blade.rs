//! A built-in compressor-blade model: a twisted, tapered cantilever plate meshed with 8-node
//! hexahedra, clamped at the root.
//!
//! Axes and units (SI: m, kg, s, Pa, N):
//! - **z radial** (span): the root face is z = 0 and is clamped; the tip is z = `length`.
//! - **x chordwise** and **y through the thickness**, before twist. At span fraction s = z/L the
//!   section is a rectangle `chord(s) × thickness`, centred on the z axis, with
//!   chord(s) = chord·(1 + (taper − 1)·s), rotated about +z by θ(s) = twist·s (right-hand rule:
//!   positive twist turns the chord from +x towards +y going up the span). At the root the
//!   chord lies along x.
//! - The leading edge is the chord end at x < 0 before twist, the trailing edge at x > 0.
//!
//! Named tip nodes (at z = L, mid-thickness): `LE` (leading edge), `MC` (mid-chord, on the z
//! axis), `TE` (trailing edge). Their **radial (z) DOFs** are the contact DOFs, see
//! [`Blade::node_dof`]. The chord and thickness element counts must be even so that these nodes
//! exist.
//!
//! DOF numbering: node (i_span, i_chord, i_thick) has index
//! `(i_span·(n_chord + 1) + i_chord)·(n_thick + 1) + i_thick`; its unclamped DOFs are
//! 3·node + {0, 1, 2} for (x, y, z). The clamped model removes the root nodes (i_span = 0), so
//! its DOF k is unclamped DOF `dofs.new_to_old[k]` = 3·node + c with nodes numbered from the
//! first span station: clamped DOF = unclamped DOF − 3·(root node count).
use super::hex8::{CORNERS, ElementKind, Mat24, Material, hex8_matrices};
use super::sparse::DofMap;
use crate::model::{Matrix, Structure};
use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use rayon::prelude::*;

/// Elements along each direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MeshDensity {
    /// Along the span (z), ≥ 1.
    pub span: usize,
    /// Along the chord (x), even, ≥ 2.
    pub chord: usize,
    /// Through the thickness (y), even, ≥ 2.
    pub thickness: usize,
}

/// Geometry, material and mesh of the blade. Lengths in m, twist in **degrees**.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BladeParams {
    /// Span L along z [m].
    pub length: f64,
    /// Root chord [m].
    pub chord: f64,
    /// Thickness [m] (constant along span and chord).
    pub thickness: f64,
    /// Total twist from root to tip [degrees], linear along the span, about +z.
    pub twist_deg: f64,
    /// Tip chord / root chord [-] (1 = untapered).
    pub taper: f64,
    pub material: Material,
    pub mesh: MeshDensity,
    pub element: ElementKind,
}

/// The two mesh presets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Preset {
    /// 24 × 8 × 2 hexahedra: 1 944 free DOFs (for tests).
    Coarse,
    /// 80 × 24 × 4 hexahedra: 30 000 free DOFs (for the benchmark).
    Fine,
}

impl Preset {
    pub fn from_name(name: &str) -> Option<Preset> {
        match name {
            "coarse" => Some(Preset::Coarse),
            "fine" => Some(Preset::Fine),
            _ => None,
        }
    }
    pub fn mesh(self) -> MeshDensity {
        match self {
            Preset::Coarse => MeshDensity { span: 24, chord: 8, thickness: 2 },
            Preset::Fine => MeshDensity { span: 80, chord: 24, thickness: 4 },
        }
    }
}

impl BladeParams {
    /// The default blade geometry (a front-stage compressor rotor blade of Ti-6Al-4V:
    /// L = 0.1 m, root chord 0.05 m, thickness 4 mm, twist 30°, taper 0.8) on a preset mesh.
    pub fn preset(p: Preset) -> BladeParams {
        BladeParams {
            length: 0.1,
            chord: 0.05,
            thickness: 0.004,
            twist_deg: 30.0,
            taper: 0.8,
            material: Material::TI6AL4V,
            mesh: p.mesh(),
            element: ElementKind::default(),
        }
    }
    pub fn coarse() -> BladeParams {
        BladeParams::preset(Preset::Coarse)
    }
    pub fn fine() -> BladeParams {
        BladeParams::preset(Preset::Fine)
    }

    /// Checks every value; the message names the parameter.
    pub fn validate(&self) -> Result<(), BladeError> {
        let bad = |field: &'static str, message: String| Err(BladeError::Parameter { field, message });
        for (field, v) in [("length", self.length), ("chord", self.chord), ("thickness", self.thickness), ("taper", self.taper)] {
            if !(v.is_finite() && v > 0.0) {
                return bad(field, format!("must be a positive finite number, got {v}"));
            }
        }
        if !self.twist_deg.is_finite() || self.twist_deg.abs() > 180.0 {
            return bad("twist", format!("must be within ±180 degrees, got {}", self.twist_deg));
        }
        let m = &self.material;
        if !(m.young.is_finite() && m.young > 0.0) {
            return bad("material.young", format!("must be positive, got {}", m.young));
        }
        if !(m.poisson > -1.0 && m.poisson < 0.5) {
            return bad("material.poisson", format!("must be in (−1, 0.5), got {}", m.poisson));
        }
        if !(m.density.is_finite() && m.density > 0.0) {
            return bad("material.density", format!("must be positive, got {}", m.density));
        }
        if self.mesh.span < 1 {
            return bad("mesh.span", "needs at least 1 element".into());
        }
        if self.mesh.chord < 2 || !self.mesh.chord.is_multiple_of(2) {
            return bad("mesh.chord", format!("must be even and ≥ 2 (a mid-chord node is needed), got {}", self.mesh.chord));
        }
        if self.mesh.thickness < 2 || !self.mesh.thickness.is_multiple_of(2) {
            return bad("mesh.thickness", format!("must be even and ≥ 2 (mid-thickness tip nodes are needed), got {}", self.mesh.thickness));
        }
        Ok(())
    }

    pub fn node_count(&self) -> usize {
        (self.mesh.span + 1) * (self.mesh.chord + 1) * (self.mesh.thickness + 1)
    }
    pub fn element_count(&self) -> usize {
        self.mesh.span * self.mesh.chord * self.mesh.thickness
    }
    /// Free DOFs after clamping the root.
    pub fn free_dof_count(&self) -> usize {
        3 * self.mesh.span * (self.mesh.chord + 1) * (self.mesh.thickness + 1)
    }
    /// Node index of grid point (i_span, i_chord, i_thick).
    pub fn node_index(&self, i_span: usize, i_chord: usize, i_thick: usize) -> usize {
        (i_span * (self.mesh.chord + 1) + i_chord) * (self.mesh.thickness + 1) + i_thick
    }
    /// Coordinates of grid point (i_span, i_chord, i_thick) [m].
    pub fn position(&self, i_span: usize, i_chord: usize, i_thick: usize) -> [f64; 3] {
        let s = i_span as f64 / self.mesh.span as f64;
        let chord = self.chord * (1.0 + (self.taper - 1.0) * s);
        let x0 = (i_chord as f64 / self.mesh.chord as f64 - 0.5) * chord;
        let y0 = (i_thick as f64 / self.mesh.thickness as f64 - 0.5) * self.thickness;
        let th = self.twist_deg.to_radians() * s;
        let (sn, cs) = th.sin_cos();
        [x0 * cs - y0 * sn, x0 * sn + y0 * cs, s * self.length]
    }
}

/// A blade that cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BladeError {
    #[error("blade generator: {field}: {message}")]
    Parameter { field: &'static str, message: String },
    #[error("blade generator: element {element}: {source}")]
    Element { element: usize, source: super::hex8::InvertedElement },
}

/// The names of the tip nodes, in chord order.
pub const TIP_NODES: [&str; 3] = ["LE", "MC", "TE"];

/// A meshed, assembled blade: M and K sparse (both triangles), root clamped.
#[derive(Clone, Debug)]
pub struct Blade {
    pub params: BladeParams,
    /// Coordinates of every node, root included [m].
    pub nodes: Vec<[f64; 3]>,
    /// Corner node indices of every hexahedron (local order of [`CORNERS`]).
    pub elements: Vec<[usize; 8]>,
    /// Consistent mass of the clamped model [kg].
    pub mass: SparseColMat<usize, f64>,
    /// Stiffness of the clamped model [N/m].
    pub stiffness: SparseColMat<usize, f64>,
    /// Unclamped (3 per node) → clamped numbering.
    pub dofs: DofMap,
}

impl Blade {
    /// Meshes and assembles the blade, root clamped.
    pub fn generate(params: &BladeParams) -> Result<Blade, BladeError> {
        build(params, true)
    }
    /// The same mesh without clamping (3 DOFs per node, rigid-body modes present): for checks.
    pub fn generate_free(params: &BladeParams) -> Result<Blade, BladeError> {
        build(params, false)
    }
    /// Number of DOFs of the (clamped) model.
    pub fn n_dof(&self) -> usize {
        self.dofs.n_new()
    }
    /// Node index of a named tip node (`LE`, `MC`, `TE`; case-sensitive).
    pub fn named_node(&self, name: &str) -> Option<usize> {
        let m = &self.params.mesh;
        let ic = match name {
            "LE" => 0,
            "MC" => m.chord / 2,
            "TE" => m.chord,
            _ => return None,
        };
        Some(self.params.node_index(m.span, ic, m.thickness / 2))
    }
    /// DOF (model numbering) of displacement component `axis` (0 = x, 1 = y, 2 = z) of `node`;
    /// `None` for clamped nodes or out-of-range arguments.
    pub fn dof(&self, node: usize, axis: usize) -> Option<usize> {
        if axis > 2 {
            return None;
        }
        self.dofs.new_index(3 * node + axis)
    }
    /// The radial (z) DOF of a named tip node (`LE`, `MC`, `TE`) in the model's numbering:
    /// the contact DOF.
    pub fn node_dof(&self, name: &str) -> Option<usize> {
        self.dof(self.named_node(name)?, 2)
    }
    /// The mid-thickness tip nodes from LE to TE (chord_elements + 1 of them): the blade-tip
    /// line a casing rubs, LE, MC and TE among them.
    pub fn tip_nodes(&self) -> Vec<usize> {
        let m = &self.params.mesh;
        (0..=m.chord).map(|ic| self.params.node_index(m.span, ic, m.thickness / 2)).collect()
    }
    /// The radial DOFs of LE, MC, TE.
    pub fn contact_dofs(&self) -> Vec<usize> {
        TIP_NODES.iter().map(|n| self.node_dof(n).expect("tip nodes exist")).collect()
    }
    /// The unclamped DOFs of the root face (z = 0).
    pub fn root_dofs(&self) -> Vec<usize> {
        let m = &self.params.mesh;
        (0..(m.chord + 1) * (m.thickness + 1)).flat_map(|node| (0..3).map(move |c| 3 * node + c)).collect()
    }
    /// The engine's structure (sparse M and K, no damping).
    pub fn structure(&self) -> Structure {
        Structure { mass: Matrix::Sparse(self.mass.clone()), stiffness: Matrix::Sparse(self.stiffness.clone()), damping: None }
    }
    /// Total mass ρ·V [kg] of the mesh (every node, root included), from the element volumes.
    pub fn total_mass(&self) -> f64 {
        self.elements.iter().map(|e| super::hex8::hex8_volume(&e.map(|a| self.nodes[a]))).sum::<f64>() * self.params.material.density
    }
}

fn build(params: &BladeParams, clamp_root: bool) -> Result<Blade, BladeError> {
    params.validate()?;
    let m = params.mesh;
    let (ns, nc, nt) = (m.span, m.chord, m.thickness);
    let n_nodes = params.node_count();
    let mut nodes = vec![[0.0; 3]; n_nodes];
    for is in 0..=ns {
        for ic in 0..=nc {
            for it in 0..=nt {
                nodes[params.node_index(is, ic, it)] = params.position(is, ic, it);
            }
        }
    }
    let mut elements = Vec::with_capacity(params.element_count());
    for is in 0..ns {
        for ic in 0..nc {
            for it in 0..nt {
                // ξ ↔ chord, η ↔ thickness, ζ ↔ span: a right-handed map, det J > 0.
                elements.push(CORNERS.map(|c| {
                    let up = |s: f64| if s > 0.0 { 1 } else { 0 };
                    params.node_index(is + up(c[2]), ic + up(c[0]), it + up(c[1]))
                }));
            }
        }
    }
    let root_nodes = (nc + 1) * (nt + 1);
    let fixed: Vec<usize> = if clamp_root { (0..3 * root_nodes).collect() } else { Vec::new() };
    let dofs = DofMap::clamping(3 * n_nodes, &fixed).expect("root DOFs are in range and not everything");

    // Element matrices, in parallel.
    let mats: Vec<(Mat24, Mat24)> = elements
        .par_iter()
        .enumerate()
        .map(|(e, conn)| hex8_matrices(&conn.map(|a| nodes[a]), &params.material, params.element).map_err(|source| BladeError::Element { element: e, source }))
        .collect::<Result<_, _>>()?;

    // Sparse pattern: node-to-node adjacency through elements, 3×3 blocks, free nodes only.
    let node_free = |q: usize| !clamp_root || q >= root_nodes;
    let mut nbr: Vec<Vec<usize>> = vec![Vec::new(); n_nodes];
    for conn in &elements {
        for &a in conn {
            for &b in conn {
                if node_free(a) && node_free(b) {
                    nbr[b].push(a);
                }
            }
        }
    }
    for l in &mut nbr {
        l.sort_unstable();
        l.dedup();
    }
    let n = dofs.n_new();
    let mut col_ptr = Vec::with_capacity(n + 1);
    col_ptr.push(0usize);
    let mut row_idx = Vec::new();
    // Column start of the first DOF of each free node (its 3 columns have the same row pattern).
    let mut node_col_start = vec![usize::MAX; n_nodes];
    for q in 0..n_nodes {
        if !node_free(q) {
            continue;
        }
        node_col_start[q] = row_idx.len();
        for _c in 0..3 {
            for &p in &nbr[q] {
                let base = dofs.new_index(3 * p).expect("free node");
                row_idx.extend_from_slice(&[base, base + 1, base + 2]);
            }
            col_ptr.push(row_idx.len());
        }
    }
    let nnz = row_idx.len();
    let mut kv = vec![0.0; nnz];
    let mut mv = vec![0.0; nnz];
    for (conn, (ke, me)) in elements.iter().zip(&mats) {
        for (b, &q) in conn.iter().enumerate() {
            if !node_free(q) {
                continue;
            }
            let col_len = 3 * nbr[q].len();
            for (a, &p) in conn.iter().enumerate() {
                if !node_free(p) {
                    continue;
                }
                let off = nbr[q].binary_search(&p).expect("adjacent");
                for cb in 0..3 {
                    let start = node_col_start[q] + cb * col_len + 3 * off;
                    for ca in 0..3 {
                        kv[start + ca] += ke[(3 * a + ca, 3 * b + cb)];
                        mv[start + ca] += me[(3 * a + ca, 3 * b + cb)];
                    }
                }
            }
        }
    }
    let sym = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
    let stiffness = SparseColMat::new(sym.clone(), kv);
    let mass = SparseColMat::new(sym, mv);
    Ok(Blade { params: *params, nodes, elements, mass, stiffness, dofs })
}

/// The scene's `generator = { kind = "blade", … }` table (without `kind`, which the scene's
/// enum consumes). Every key is optional and overrides the preset:
///
/// ```toml
/// generator = { kind = "blade", preset = "coarse", length = 0.1, chord = 0.05, thickness = 0.004,
///               twist_deg = 30.0, taper = 0.8, young = 114e9, poisson = 0.34, density = 4430.0,
///               span_elements = 24, chord_elements = 8, thickness_elements = 2,
///               element = "hex8-incompatible" }
/// ```
#[derive(Clone, Debug, Default, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BladeSpec {
    /// `"coarse"` (default) or `"fine"`.
    pub preset: Option<String>,
    /// Span [m].
    pub length: Option<f64>,
    /// Root chord [m].
    pub chord: Option<f64>,
    /// Thickness [m].
    pub thickness: Option<f64>,
    /// Total twist root → tip [degrees].
    pub twist_deg: Option<f64>,
    /// Tip chord / root chord.
    pub taper: Option<f64>,
    /// Young's modulus [Pa].
    pub young: Option<f64>,
    /// Poisson's ratio.
    pub poisson: Option<f64>,
    /// Density [kg/m³].
    pub density: Option<f64>,
    pub span_elements: Option<usize>,
    pub chord_elements: Option<usize>,
    pub thickness_elements: Option<usize>,
    /// `"hex8-incompatible"` (default) or `"hex8"`.
    pub element: Option<String>,
}

impl BladeSpec {
    /// The parameters this spec describes (validated).
    pub fn params(&self) -> Result<BladeParams, BladeError> {
        let bad = |field: &'static str, message: String| BladeError::Parameter { field, message };
        let preset = match self.preset.as_deref() {
            None => Preset::Coarse,
            Some(name) => Preset::from_name(name).ok_or_else(|| bad("preset", format!("`{name}` is not a preset; expected `coarse` or `fine`")))?,
        };
        let mut p = BladeParams::preset(preset);
        p.length = self.length.unwrap_or(p.length);
        p.chord = self.chord.unwrap_or(p.chord);
        p.thickness = self.thickness.unwrap_or(p.thickness);
        p.twist_deg = self.twist_deg.unwrap_or(p.twist_deg);
        p.taper = self.taper.unwrap_or(p.taper);
        p.material.young = self.young.unwrap_or(p.material.young);
        p.material.poisson = self.poisson.unwrap_or(p.material.poisson);
        p.material.density = self.density.unwrap_or(p.material.density);
        p.mesh.span = self.span_elements.unwrap_or(p.mesh.span);
        p.mesh.chord = self.chord_elements.unwrap_or(p.mesh.chord);
        p.mesh.thickness = self.thickness_elements.unwrap_or(p.mesh.thickness);
        p.element = match self.element.as_deref() {
            None | Some("hex8-incompatible") => ElementKind::Hex8Incompatible,
            Some("hex8") => ElementKind::Hex8,
            Some(other) => return Err(bad("element", format!("`{other}` is not an element; expected `hex8-incompatible` or `hex8`"))),
        };
        p.validate()?;
        Ok(p)
    }
}
