//! Materials: a BSDF whose parameters may be textures. Evaluated at a hit into a plain [`Bsdf`]; an
//! untextured material is that `Bsdf` already.

use crate::bsdf::{textured_reflectance, Bsdf, Diffuse, LaneValue, PerLaneKernel, Tint};
use crate::error::{Error, Result};
use crate::geometry::Mesh;
use crate::math::lanes::Real;
use crate::math::param::PER_LANE;
use crate::math::simd::{Float8, Mask8};
use crate::math::Frame;
use crate::props::{Props, Value};
use crate::spectrum::Rgb;
use crate::texture::{MeshAttribute, SurfaceTexture, Texture};
use glam::{Vec2, Vec3};
use std::borrow::Cow;
use std::collections::HashMap;
use std::sync::{Mutex, RwLock};

/// Most distinct texture-value combinations a [`Material::Textured`] keeps built models for (2026-11:
/// checkerboards and binary masks have a handful; continuous textures miss the cache and rebuild).
const CACHE_CAPACITY: usize = 256;

/// BSDF parameters that take a float, not a colour: a texture there is read with Mitsuba's scalar lookup
/// ([`Texture::eval_1`]), which differs from the colour lookup for checkerboards.
pub(crate) const SCALAR_PARAMETERS: &[&str] = &[
    "alpha",
    "alpha_u",
    "alpha_v",
    "opacity",
    "weight",
    "exponent",
    // principled
    "roughness",
    "anisotropic",
    "metallic",
    "spec_trans",
    "spec_tint",
    "sheen",
    "sheen_tint",
    "flatness",
    "clearcoat",
    "clearcoat_gloss",
];

/// One shape's reflection model.
#[derive(Debug)]
pub enum Material {
    Fixed(Bsdf),
    /// A `diffuse` whose reflectance is a texture (the common case, built without `Props`).
    TexturedDiffuse(Texture),
    /// A model whose every texture sets a reflectance it reads as it is ([`Bsdf::reflectance_slot`]) or a
    /// float it can take at once ([`Bsdf::set_float`]: a blend's weight, a roughness): built once, and
    /// at a hit copied with the textures' values written into it — the model [`Material::Textured`] would
    /// build from the same values, without `Props`. Each texture with its parameter and how it is read.
    Slotted {
        model: Bsdf,
        textures: Vec<(Slot, SurfaceTexture, Lookup)>,
        /// Where every texture is a tint ([`Bsdf::tint`]) or a parameter the model takes per lane
        /// ([`Bsdf::per_lane_kernel`]): the model with the tinted parameters at 1, and how each texture
        /// applies, in `textures`' order ([`Material::lanes_at`]).
        in_lanes: Option<(Bsdf, Vec<InLanes>)>,
    },
    /// Any other BSDF with texture parameters: the description without them, and the textures with their
    /// parameter paths. Rebuilt at every hit from a copy of the template (`Props` tracks which parameters
    /// were read, so it is not `Sync`: the template sits behind a mutex held only for the copy). A slow,
    /// general path; models gain direct texture support as they need it, like `TexturedDiffuse`.
    ///
    /// Built models are kept per combination of texture values (bit patterns) up to `CACHE_CAPACITY`
    /// entries, so textures with few distinct values (checkerboards, masks) build each model once.
    Textured {
        template: Mutex<Props>,
        textures: Vec<(Vec<String>, SurfaceTexture, Lookup)>,
        cache: RwLock<HashMap<Vec<u32>, Bsdf>>,
    },
}

/// How the packets apply a texture of a slotted material in lanes (`Material::Slotted`'s `in_lanes`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum InLanes {
    /// It scales the model's values in this lobe.
    Tint(Tint),
    /// The model takes it per lane: a kernel with each lane's value ([`Bsdf::per_lane_kernel`]).
    Value,
}

/// What the lanes of a packet on one slotted material run ([`Material::lanes_at`]): `kernel` (with
/// parameters per lane) or else `model`, for all of them, each lane's values then scaled by its tint of
/// reflection (`tints[0]`) or transmission (`tints[1]`) where `tinted`.
#[derive(Clone, Debug)]
pub struct LaneMaterial<'a> {
    pub model: &'a Bsdf,
    pub kernel: Option<PerLaneKernel<'a>>,
    pub tinted: bool,
    pub tints: [[Float8; 3]; 2],
}

/// Where a slotted texture's value is written: the nested models on the way from the material's model
/// (at each level the index of the description among its parent's nested ones and their count, in
/// `Props::nested`'s order: see [`Bsdf::for_nested_models`]) and the parameter's name in the last.
#[derive(Clone, Debug, PartialEq)]
pub struct Slot {
    route: Vec<(usize, usize)>,
    name: String,
}

impl Slot {
    /// The slot of the texture at `path` (from `Props::take_textures`) in a model built from `template`.
    pub(crate) fn of(template: &Props, path: &[String]) -> Option<Slot> {
        let (name, parents) = path.split_last()?;
        let mut props = template;
        let mut route = Vec::with_capacity(parents.len());
        for parent in parents {
            let nested = props.nested_named();
            let k = nested.iter().position(|(n, _)| n == parent)?;
            route.push((k, nested.len()));
            props = nested[k].1;
        }
        Some(Slot { route, name: name.clone() })
    }

    /// Whether this is parameter `name` of the material's own model.
    pub(crate) fn is_top(&self, name: &str) -> bool {
        self.route.is_empty() && self.name == name
    }

    /// Write `value` into every model the route reaches (a float with [`Bsdf::set_float`], a colour into
    /// [`Bsdf::reflectance_slot`] clamped to [0, 1]: both clamped as the rebuilt model's readers clamp a
    /// texture's value, [`Props::set_texture_value`]): whether it reached one and each took the value.
    pub(crate) fn write(&self, model: &mut Bsdf, value: &TextureValue) -> bool {
        fn visit(model: &mut Bsdf, route: &[(usize, usize)], name: &str, value: &TextureValue) -> bool {
            match (route, value) {
                ([], TextureValue::Scalar(v)) => model.set_float(name, *v),
                ([], TextureValue::Colour(c)) => model.reflectance_slot(name).map(|r| *r = c.map(textured_reflectance)).is_some(),
                ([(k, count), rest @ ..], _) => {
                    let mut ok = true;
                    let reached = model.for_nested_models(*k, *count, &mut |m| ok &= visit(m, rest, name, value));
                    ok && reached > 0
                }
            }
        }
        visit(model, &self.route, &self.name, value)
    }
}

/// How a material reads one of its textures at a hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Lookup {
    /// A colour parameter: [`Texture::eval`].
    Colour,
    /// A float parameter (in `SCALAR_PARAMETERS`): [`Texture::eval_1`].
    Float,
    /// A `bumpmap`'s height field, times `scale`: its gradient turns the shading normal, which the
    /// `bumpmap` (a [`crate::bsdf::NormalMap`]) reads as its `normalmap` colour ([`bump_normal`]).
    Bump { scale: f32 },
}

/// The surface at a hit where bump maps and mesh attributes are read: the geometric normal, the shading
/// frame, ∂p/∂u and ∂p/∂v of the shape's parameterisation (world space;
/// [`crate::geometry::Shape::uv_partials`]), and the mesh, triangle and point (where the shape is a mesh).
#[derive(Clone, Copy, Debug)]
pub struct Differentials<'a> {
    pub n: Vec3,
    pub shading: Frame,
    pub dp_du: Vec3,
    pub dp_dv: Vec3,
    pub mesh: Option<&'a Mesh>,
    pub prim: u32,
    pub p: Vec3,
}

impl Differentials<'_> {
    /// The mesh attribute `m` here, scaled (black where the shape has no such attribute: the scene checks
    /// that when it is built).
    fn attribute(&self, m: &MeshAttribute) -> Rgb {
        let Some(mesh) = self.mesh else { return Rgb::ZERO };
        match mesh.attributes().iter().position(|a| a.name == m.name) {
            Some(i) => mesh.attribute_at(i, self.prim, self.p) * m.scale,
            None => Rgb::ZERO,
        }
    }
}

/// The normal a height field with gradient `grad` (∂h/∂u, ∂h/∂v, already scaled) gives the surface `d`,
/// in its shading frame and encoded as `normalmap` colours are ((n + 1)/2): Mitsuba 3's `bumpmap`
/// (Blinn 1978, ignoring the normal's own derivatives): ∂p/∂u′ = ∂p/∂u + n (∂h/∂u − n·∂p/∂u) with n the
/// shading normal, likewise for v, n′ = ∂p/∂u′ × ∂p/∂v′ turned to the side of the geometric normal.
/// Without a surface (`None`), or where n′ is degenerate, the shading normal itself.
#[must_use]
pub fn bump_normal(grad: Vec2, d: Option<&Differentials<'_>>) -> Rgb {
    let flat = Rgb::new(0.5, 0.5, 1.0);
    let Some(d) = d else { return flat };
    let ns = d.shading.n;
    let dp_du = d.dp_du + ns * (grad.x - ns.dot(d.dp_du));
    let dp_dv = d.dp_dv + ns * (grad.y - ns.dot(d.dp_dv));
    let mut n = dp_du.cross(dp_dv);
    if d.n.dot(n) < 0.0 {
        n = -n;
    }
    match d.shading.to_local(n).try_normalize() {
        Some(l) => Rgb::new(0.5 * l.x + 0.5, 0.5 * l.y + 0.5, 0.5 * l.z + 0.5),
        None => flat,
    }
}

impl Material {
    /// Build from a `<bsdf>` description (textures included).
    pub fn from_props(p: &Props) -> Result<Material> {
        let material = Self::rebuilt(p)?;
        let Material::Textured { template, textures, .. } = &material else { return Ok(material) };
        // Built once now, so that parameter errors surface at load time; that model is the slotted form's
        // where every texture has a slot in it (in the model itself or in models it holds as they are).
        let model = material.try_at(Vec2::splat(0.5), None)?.into_owned();
        let template = template.lock().map_or_else(|poisoned| poisoned.into_inner().clone(), |t| t.clone());
        let slots: Option<Vec<Slot>> = textures
            .iter()
            .map(|(path, _, lookup)| {
                let slot = Slot::of(&template, path)?;
                let probe = if matches!(lookup, Lookup::Float) { TextureValue::Scalar(0.5) } else { TextureValue::Colour(Rgb::splat(0.5)) };
                slot.write(&mut model.clone(), &probe).then_some(slot)
            })
            .collect();
        if let Some(slots) = slots {
            let textures: Vec<_> = slots.into_iter().zip(textures).map(|(slot, (_, t, lookup))| (slot, t.clone(), *lookup)).collect();
            let in_lanes = Self::in_lanes(&model, &textures);
            return Ok(Material::Slotted { model, textures, in_lanes });
        }
        Ok(material)
    }

    /// The lane form of a slotted material (see `Material::Slotted`): every texture read at texture
    /// coordinates, either as a colour on a parameter that tints its model ([`Bsdf::tint`]), reached through
    /// nothing but `twosided`s of one nested model (a blend's component, or one side of two, is not a tint
    /// of the whole), or on a parameter of the model itself that it takes per lane (a roughness, a base
    /// colour: [`Bsdf::per_lane_kernel`]).
    fn in_lanes(model: &Bsdf, textures: &[(Slot, SurfaceTexture, Lookup)]) -> Option<(Bsdf, Vec<InLanes>)> {
        let mut base = model.clone();
        let mut how = Vec::with_capacity(textures.len());
        for (slot, texture, lookup) in textures {
            if !matches!(texture, SurfaceTexture::Uv(_)) {
                return None;
            }
            let probe = match lookup {
                Lookup::Float => LaneValue::Float([0.5; PER_LANE]),
                _ => LaneValue::Colour([[0.5; PER_LANE]; 3]),
            };
            match lookup {
                Lookup::Float | Lookup::Colour
                    if slot.route.is_empty() && model.per_lane_kernel([(slot.name.as_str(), probe)]).is_some() =>
                {
                    how.push(InLanes::Value);
                }
                Lookup::Colour => {
                    let mut leaf = &mut base;
                    for &step in &slot.route {
                        if step != (0, 1) {
                            return None;
                        }
                        leaf = leaf.both_sides()?;
                    }
                    how.push(InLanes::Tint(leaf.tint(&slot.name)?));
                    if !slot.write(&mut base, &TextureValue::Colour(Rgb::ONE)) {
                        return None;
                    }
                }
                _ => return None,
            }
        }
        Some((base, how))
    }

    /// The material without slots: `Fixed`, `TexturedDiffuse`, or `Textured` (built again at each hit).
    fn rebuilt(p: &Props) -> Result<Material> {
        let mut template = p.clone();
        let taken = template.take_textures();
        if taken.is_empty() {
            return Ok(Material::Fixed(Bsdf::from_props(p)?));
        }
        let mut bumped: Vec<&[String]> = Vec::new();
        let mut textures = Vec::with_capacity(taken.len());
        for (path, t) in &taken {
            let texture = SurfaceTexture::from_props(t)?;
            let parent = &path[..path.len() - 1];
            let bump = template.nested_at(parent).filter(|b| b.plugin_type() == "bumpmap");
            if let Some(b) = bump {
                if matches!(texture, SurfaceTexture::MeshAttribute(_)) {
                    return Err(Error::spec(t.at(), "a `bumpmap`'s height field must be a texture with a gradient (bitmap, checkerboard)"));
                }
                // The height field sets the bumpmap's normal (a parameter `normalmap` of that model).
                if bumped.contains(&parent) {
                    return Err(Error::spec(t.at(), "a `bumpmap` takes one texture (its height field)"));
                }
                bumped.push(parent);
                let scale = b.float_in("scale", 1.0, f32::MIN, f32::MAX)?;
                textures.push(([parent, &["normalmap".to_string()]].concat(), texture, Lookup::Bump { scale }));
            } else {
                let float = path.last().is_some_and(|name| SCALAR_PARAMETERS.contains(&name.as_str()));
                textures.push((path.clone(), texture, if float { Lookup::Float } else { Lookup::Colour }));
            }
        }
        Ok(match (template.plugin_type(), textures.as_slice()) {
            ("diffuse", [(path, SurfaceTexture::Uv(t), Lookup::Colour)]) if path == &["reflectance"] => {
                Material::TexturedDiffuse(t.clone())
            }
            _ => Material::Textured { template: Mutex::new(template), textures, cache: RwLock::new(HashMap::new()) },
        })
    }

    fn try_at(&self, uv: Vec2, surface: Option<&Differentials<'_>>) -> Result<Cow<'_, Bsdf>> {
        Ok(match self {
            Material::Fixed(b) => Cow::Borrowed(b),
            Material::TexturedDiffuse(t) => Cow::Owned(Bsdf::Diffuse(Diffuse::new(Self::texel(t, uv)))),
            Material::Slotted { model, textures, .. } => {
                let mut model = model.clone();
                for (slot, t, lookup) in textures {
                    let value = TextureValue::of(t, *lookup, uv, surface);
                    // A value out of range is clamped into it (`Slot::write`); one that is not a number fails
                    // as it would in the rebuilt model.
                    if !value.is_finite() {
                        return Err(Error::spec("", format!("texture value of `{}` is not a finite number", slot.name)));
                    }
                    let written = slot.write(&mut model, &value);
                    debug_assert!(written, "slots checked when the material was built");
                }
                Cow::Owned(model)
            }
            Material::Textured { template, textures, cache } => {
                let values: Vec<TextureValue> = textures.iter().map(|(_, t, lookup)| TextureValue::of(t, *lookup, uv, surface)).collect();
                let key: Vec<u32> = values.iter().flat_map(TextureValue::bits).collect();
                if let Some(b) = cache.read().ok().and_then(|c| c.get(&key).cloned()) {
                    return Ok(Cow::Owned(b));
                }
                let mut p = template.lock().map_or_else(|poisoned| poisoned.into_inner().clone(), |t| t.clone());
                let at = p.at().to_string();
                for ((path, ..), value) in textures.iter().zip(&values) {
                    p.set_texture_value(path, value.to_value(), &at);
                }
                let bsdf = Bsdf::from_props(&p)?;
                if let Ok(mut c) = cache.write() {
                    if c.len() < CACHE_CAPACITY {
                        c.insert(key, bsdf.clone());
                    }
                }
                Cow::Owned(bsdf)
            }
        })
    }

    /// Whether the material reads textures (and so needs texture coordinates at hits).
    #[must_use]
    pub fn is_textured(&self) -> bool {
        !matches!(self, Material::Fixed(_))
    }

    /// A textured `diffuse`'s reflectance at `uv`: the texture's value clamped to [0, 1].
    #[inline]
    fn texel(t: &Texture, uv: Vec2) -> crate::spectrum::Rgb {
        Self::clamped(t.eval(uv))
    }

    /// A texture value as a reflectance: clamped to [0, 1].
    #[inline]
    fn clamped(c: crate::spectrum::Rgb) -> crate::spectrum::Rgb {
        c.map(textured_reflectance)
    }

    /// For a `diffuse` material (textured or not), its reflectance at `uv` — what [`Self::at`] would build a
    /// [`Diffuse`] of, without building it (the renderer's packets evaluate diffuse surfaces in lanes).
    #[inline]
    #[must_use]
    pub fn diffuse_reflectance(&self, uv: Vec2) -> Option<crate::spectrum::Rgb> {
        match self {
            Material::Fixed(Bsdf::Diffuse(d)) => Some(d.reflectance),
            Material::TexturedDiffuse(t) => Some(Self::texel(t, uv)),
            _ => None,
        }
    }

    /// [`Self::diffuse_reflectance`] in lanes, at texture coordinates (`u`, `v`) of the lanes set in `lanes`
    /// (the others are left unspecified): a constant `diffuse`'s reflectance, a checkerboard's or a
    /// bitmap's (the same values as one lane at a time). `None` for other materials.
    #[inline]
    #[must_use]
    pub fn diffuse_reflectance_lanes(&self, u: Float8, v: Float8, lanes: u32) -> Option<[Float8; 3]> {
        match self {
            Material::Fixed(Bsdf::Diffuse(d)) => Some(d.reflectance.0.map(Float8::splat)),
            Material::TexturedDiffuse(t) => Some(Self::texels(t, u, v, lanes)),
            _ => None,
        }
    }

    /// For a material whose every texture is a tint or a parameter taken per lane (see
    /// `Material::Slotted`): what its lanes run at texture coordinates (`u`, `v`) of the lanes set in
    /// `lanes` (the others' tints are left unspecified) — the values of [`Self::at`]'s model in each lane,
    /// to rounding (the model multiplies in its tints in its own order). `None` for other materials, and
    /// where a texture taken per lane is not a finite number in one of the lanes (each lane's own model then
    /// reports it, as [`Self::at`] does).
    #[inline]
    #[must_use]
    pub fn lanes_at(&self, u: Float8, v: Float8, lanes: u32) -> Option<LaneMaterial<'_>> {
        let Material::Slotted { textures, in_lanes: Some((model, how)), .. } = self else { return None };
        let mut tints = [[Float8::splat(1.0); 3]; 2];
        let (mut tinted, mut per_lane) = (false, false);
        for ((_, texture, _), how) in textures.iter().zip(how) {
            let SurfaceTexture::Uv(t) = texture else { return None };
            match how {
                InLanes::Tint(lobe) => {
                    let tint = &mut tints[match lobe {
                        Tint::Reflection => 0,
                        Tint::Transmission => 1,
                    }];
                    let c = Self::texels(t, u, v, lanes);
                    *tint = std::array::from_fn(|i| tint[i] * c[i]);
                    tinted = true;
                }
                InLanes::Value => per_lane = true,
            }
        }
        let mut kernel = None;
        if per_lane {
            // The other lanes hold a valid value, so that the kernel's numbers stay tame there.
            let (m, mut finite) = (Mask8::from_bitmask(lanes), true);
            let mut lane_value = |v: Float8, other: f32| {
                finite &= !Float8::any(m & !v.is_finite());
                Float8::select(m, v, Float8::splat(other)).to_array()
            };
            // Evaluated as the kernel reads them; it reads all before it returns one, so `finite` then
            // covers every texture ([`Bsdf::per_lane_kernel`]).
            let values = textures.iter().zip(how).filter(|(_, how)| **how == InLanes::Value).filter_map(|((slot, texture, lookup), _)| {
                let SurfaceTexture::Uv(t) = texture else { return None };
                let value = match lookup {
                    Lookup::Float => LaneValue::Float(lane_value(t.eval_1_lanes(u, v, lanes), 1.0)),
                    _ => LaneValue::Colour(t.eval_lanes(u, v, lanes).map(|c| lane_value(c, 0.5))),
                };
                Some((slot.name.as_str(), value))
            });
            kernel = model.per_lane_kernel(values);
            if !finite || kernel.is_none() {
                return None;
            }
        }
        Some(LaneMaterial { model, kernel, tinted, tints })
    }

    /// A texture's colours at (`u`, `v`) in lanes as reflectances (clamped to [0, 1]; [`Self::texel`] in
    /// each lane).
    #[inline]
    fn texels(t: &Texture, u: Float8, v: Float8, lanes: u32) -> [Float8; 3] {
        t.eval_lanes(u, v, lanes).map(|c| Real::clamp(c, 0.0, 1.0)) // textured_reflectance in lanes
    }

    /// The model this material's models at hits are copies of, where it has one: a `Fixed` model, or a
    /// `Slotted` one before its textures are written into it ([`Bsdf::kernel_of_lanes`] takes the copies).
    #[must_use]
    pub fn model(&self) -> Option<&Bsdf> {
        match self {
            Material::Fixed(model) | Material::Slotted { model, .. } => Some(model),
            Material::TexturedDiffuse(_) | Material::Textured { .. } => None,
        }
    }

    /// The BSDF at texture coordinates `uv`. A texture's value outside its parameter's range is clamped
    /// into it (`Props::set_texture_value`); one a model still rejects (not a number) gives a black
    /// diffuse rather than a panic; load-time validation catches constant mistakes.
    #[must_use]
    pub fn at(&self, uv: Vec2) -> Cow<'_, Bsdf> {
        // The common case without the `Result` around a large `Cow` (2026-11: 2 % of a Cornell box render).
        if let Material::Fixed(b) = self {
            return Cow::Borrowed(b);
        }
        self.at_surface(uv, None)
    }

    /// Each texture with how it is read (none for `Fixed`, and `TexturedDiffuse`'s reads a colour at uv).
    fn lookups(&self) -> impl Iterator<Item = (&SurfaceTexture, Lookup)> {
        let (slotted, textured) = match self {
            Material::Slotted { textures, .. } => (Some(textures), None),
            Material::Textured { textures, .. } => (None, Some(textures)),
            Material::Fixed(_) | Material::TexturedDiffuse(_) => (None, None),
        };
        let slotted = slotted.into_iter().flatten().map(|(_, t, l)| (t, *l));
        slotted.chain(textured.into_iter().flatten().map(|(_, t, l)| (t, *l)))
    }

    /// Whether the material reads the surface (a bump map, a mesh attribute): evaluate it with
    /// [`Self::at_surface`] then.
    #[must_use]
    pub fn reads_surface(&self) -> bool {
        self.lookups().any(|(t, l)| matches!(l, Lookup::Bump { .. }) || matches!(t, SurfaceTexture::MeshAttribute(_)))
    }

    /// The mesh attributes the material reads, for the scene to check that its shape has them.
    #[must_use]
    pub fn mesh_attributes(&self) -> Vec<&MeshAttribute> {
        self.lookups().filter_map(|(t, _)| if let SurfaceTexture::MeshAttribute(m) = t { Some(m) } else { None }).collect()
    }

    /// [`Self::at`] on the surface `surface` (where bump maps read it; without it, they leave the shading
    /// normal as it is).
    #[must_use]
    pub fn at_surface(&self, uv: Vec2, surface: Option<&Differentials<'_>>) -> Cow<'_, Bsdf> {
        if let Material::Fixed(b) = self {
            return Cow::Borrowed(b);
        }
        self.try_at(uv, surface).unwrap_or_else(|_| Cow::Owned(Bsdf::Diffuse(Diffuse::new(crate::spectrum::Rgb::ZERO))))
    }
}

/// A texture's value at a hit: a float for the parameters in `SCALAR_PARAMETERS`, else a colour.
pub(crate) enum TextureValue {
    Scalar(f32),
    Colour(crate::spectrum::Rgb),
}

impl TextureValue {
    fn of(t: &SurfaceTexture, lookup: Lookup, uv: Vec2, surface: Option<&Differentials<'_>>) -> Self {
        match (t, lookup) {
            (SurfaceTexture::Uv(t), Lookup::Float) => TextureValue::Scalar(t.eval_1(uv)),
            (SurfaceTexture::Uv(t), Lookup::Colour) => TextureValue::Colour(t.eval(uv)),
            (SurfaceTexture::Uv(t), Lookup::Bump { scale }) => TextureValue::Colour(bump_normal(t.eval_1_grad(uv) * scale, surface)),
            (SurfaceTexture::MeshAttribute(m), lookup) => {
                let c = surface.map_or(Rgb::ZERO, |s| s.attribute(m));
                match lookup {
                    Lookup::Float => TextureValue::Scalar(c.luminance()),
                    _ => TextureValue::Colour(c),
                }
            }
        }
    }

    fn is_finite(&self) -> bool {
        match self {
            TextureValue::Scalar(v) => v.is_finite(),
            TextureValue::Colour(c) => c.0.iter().all(|v| v.is_finite()),
        }
    }

    fn bits(&self) -> Vec<u32> {
        match self {
            TextureValue::Scalar(v) => vec![v.to_bits()],
            TextureValue::Colour(c) => c.0.iter().map(|v| v.to_bits()).collect(),
        }
    }

    fn to_value(&self) -> Value {
        match self {
            TextureValue::Scalar(v) => Value::Number(f64::from(*v)),
            TextureValue::Colour(c) => Value::List(c.to_f64().to_vec()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A texture on a parameter: the parameter's name and the checkerboard's two colours.
    type Textured<'a> = (&'a str, &'a str, &'a str);

    /// A `<bsdf>` with checkerboards (of colours `c0`, `c1`) on the parameters `textured`.
    fn props(plugin: &str, extra: &str, textured: &[Textured<'_>]) -> Props {
        let textures: String = textured
            .iter()
            .map(|(name, c0, c1)| {
                format!(
                    r#"<texture type="checkerboard" name="{name}"><rgb name="color0" value="{c0}"/><rgb name="color1" value="{c1}"/>
                       <transform name="to_uv"><scale x="3" y="2"/></transform></texture>"#
                )
            })
            .collect();
        Props::from_xml_bsdf(&format!(r#"<bsdf type="{plugin}">{extra}{textures}</bsdf>"#), "test.xml").unwrap()
    }

    /// Every texture the slotted form writes gives the model that building it again from the texture's
    /// values gives, bit for bit, over each model's reflectances and roughnesses (one and two textures at
    /// once); a value out of the parameter's range is clamped into it in both forms (a reflectance to
    /// [0, 1], a blend weight to [0, 1], a roughness to [10⁻⁴, 10]: Mitsuba's floor) — never a black
    /// surface; models whose textures have no slot (energy compensation, a nested model) are built again
    /// and clamp alike.
    #[test]
    fn slotted_textures_give_the_rebuilt_models() {
        let (a, b) = ("0.9, 0.25, 0.5", "0.1, 0.7, 1");
        let blend = r#"<bsdf type="diffuse"/><bsdf type="roughconductor"><string name="material" value="Cu"/></bsdf>"#;
        let cases: Vec<(&str, &str, Vec<Textured<'_>>)> = vec![
            ("conductor", r#"<string name="material" value="Au"/>"#, vec![("specular_reflectance", a, b)]),
            ("roughconductor", r#"<float name="alpha" value="0.3"/>"#, vec![("specular_reflectance", a, b)]),
            ("dielectric", "", vec![("specular_reflectance", a, b), ("specular_transmittance", b, a)]),
            ("thindielectric", "", vec![("specular_transmittance", a, b)]),
            ("roughdielectric", r#"<string name="distribution" value="ggx"/>"#, vec![("specular_transmittance", a, b)]),
            ("roughdielectric", "", vec![("specular_reflectance", a, b)]),
            ("plastic", r#"<boolean name="nonlinear" value="true"/>"#, vec![("diffuse_reflectance", a, b), ("specular_reflectance", b, a)]),
            ("roughplastic", "", vec![("diffuse_reflectance", a, b)]),
            ("roughplastic", r#"<string name="distribution" value="ggx"/>"#, vec![("specular_reflectance", a, b)]),
            ("roughplastic", "", vec![("diffuse_reflectance", a, "0.5, 1.5, 0.5")]),
            ("blendbsdf", blend, vec![("weight", "0.2", "0.7")]),
            ("principled", "", vec![("base_color", a, b)]),
            (
                "principled",
                r#"<float name="roughness" value="0.3"/>"#,
                vec![("metallic", "0.7", "0.1"), ("clearcoat", "0.9", "0.1"), ("spec_trans", "0.2", "0.8"), ("sheen", "0.2", "0.9")],
            ),
            ("principled", "", vec![("roughness", "0.05", "0.8"), ("anisotropic", "0.05", "0.8"), ("flatness", "1", "0")]),
            ("blendbsdf", blend, vec![("weight", "1.5", "0.3")]),
            ("roughconductor", "", vec![("alpha", "0.1", "0.3")]),
            ("roughconductor", r#"<string name="distribution" value="ggx"/>"#, vec![("alpha_u", "0.05", "0.4"), ("alpha_v", "0.3", "0")]),
            ("roughconductor", r#"<string name="material" value="Cu"/>"#, vec![("alpha", "0", "0.2"), ("specular_reflectance", a, b)]),
            ("roughdielectric", "", vec![("alpha", "0", "20")]),
            ("roughdielectric", r#"<string name="distribution" value="ggx"/>"#, vec![("alpha_v", "0.01", "0.5")]),
            ("torrance_sparrow", "", vec![("alpha", "0.02", "0.6")]),
        ];
        for (plugin, extra, textured) in &cases {
            let p = props(plugin, extra, textured);
            let slotted = Material::from_props(&p).unwrap();
            assert!(matches!(slotted, Material::Slotted { .. }), "{plugin} {textured:?}");
            let rebuilt = Material::rebuilt(&p).unwrap();
            for i in 0..64 {
                let uv = Vec2::new((i as f32 * 0.37).fract(), (i as f32 * 0.61).fract());
                assert_eq!(slotted.at(uv), rebuilt.at(uv), "{plugin} {textured:?} at {uv}");
            }
        }
        // Out-of-range values are the clamped ones (the test above compared those cases to the rebuilt
        // models, which clamp alike).
        for (plugin, extra, outside, inside) in [
            ("roughplastic", "", ("diffuse_reflectance", a, "0.5, 1.5, 0.5"), ("diffuse_reflectance", a, "0.5, 1, 0.5")),
            ("blendbsdf", blend, ("weight", "1.5", "0.3"), ("weight", "1", "0.3")),
            ("roughdielectric", "", ("alpha", "0", "20"), ("alpha", "0.0001", "10")),
            ("roughconductor", r#"<boolean name="energy_compensation" value="true"/>"#, ("alpha", "0", "0.3"), ("alpha", "0.0001", "0.3")),
        ] {
            let (clamped, within) = (
                Material::from_props(&props(plugin, extra, &[outside])).unwrap(),
                Material::from_props(&props(plugin, extra, &[inside])).unwrap(),
            );
            for i in 0..64 {
                let uv = Vec2::new(i as f32 / 64.0, 0.3);
                assert_eq!(clamped.at(uv), within.at(uv), "{plugin} {outside:?} at {uv}");
                assert!(!matches!(*clamped.at(uv), Bsdf::Diffuse(_)), "{plugin} {outside:?} at {uv}");
            }
        }

        for (plugin, extra, textured) in [
            ("roughconductor", r#"<boolean name="energy_compensation" value="true"/>"#, vec![("alpha", "0.1", "0.3")]),
            ("roughconductor", r#"<boolean name="energy_compensation" value="true"/>"#, vec![("specular_reflectance", a, b)]),
            ("roughplastic", r#"<boolean name="energy_compensation" value="true"/>"#, vec![("diffuse_reflectance", a, b)]),
        ] {
            let m = Material::from_props(&props(plugin, extra, &textured)).unwrap();
            assert!(matches!(m, Material::Textured { .. }), "{plugin} {textured:?}");
        }
    }

    /// Textures on models held by `twosided` and `blendbsdf` (as Blender's exporter writes every
    /// material) are slotted too, and give the rebuilt models bit for bit: one nested model (both sides),
    /// two (each side its own), a blend inside a two-sided model, a blend's nested model and weight.
    #[test]
    fn textures_in_nested_models_are_slotted() {
        let checker = |name: &str, c0: &str, c1: &str| {
            format!(
                r#"<texture type="checkerboard" name="{name}"><rgb name="color0" value="{c0}"/><rgb name="color1" value="{c1}"/>
                   <transform name="to_uv"><scale x="3" y="2"/></transform></texture>"#
            )
        };
        let (a, b) = ("0.9, 0.25, 0.5", "0.1, 0.7, 1");
        let diffuse = format!(r#"<bsdf type="diffuse">{}</bsdf>"#, checker("reflectance", a, b));
        let plastic = format!(r#"<bsdf type="roughplastic">{}</bsdf>"#, checker("diffuse_reflectance", b, a));
        let metal =
            format!(r#"<bsdf type="conductor"><string name="material" value="Au"/>{}</bsdf>"#, checker("specular_reflectance", a, a));
        let blend = format!(r#"<bsdf type="blendbsdf">{}{diffuse}<bsdf type="dielectric"/></bsdf>"#, checker("weight", "0.2", "0.7"));
        for (xml, slotted) in [
            (format!(r#"<bsdf type="twosided">{diffuse}</bsdf>"#), true),
            (format!(r#"<bsdf type="twosided">{plastic}{metal}</bsdf>"#), true),
            (format!(r#"<bsdf type="twosided">{diffuse}<bsdf type="diffuse"/></bsdf>"#), true),
            (
                format!(
                    r#"<bsdf type="twosided"><bsdf type="blendbsdf">{}{diffuse}{metal}</bsdf></bsdf>"#,
                    checker("weight", "0.1", "0.6")
                ),
                true,
            ),
            (blend.clone(), true),
            (format!(r#"<bsdf type="twosided"><bsdf type="roughconductor">{}</bsdf></bsdf>"#, checker("alpha", "0.1", "0.3")), true),
            (
                format!(
                    r#"<bsdf type="twosided"><bsdf type="roughconductor"><boolean name="energy_compensation" value="true"/>{}</bsdf></bsdf>"#,
                    checker("alpha", "0.1", "0.3")
                ),
                false,
            ),
            (format!(r#"<bsdf type="mask">{diffuse}</bsdf>"#), false),
        ] {
            let p = Props::from_xml_bsdf(&xml, "test.xml").unwrap();
            let m = Material::from_props(&p).unwrap();
            assert_eq!(matches!(m, Material::Slotted { .. }), slotted, "{xml}");
            let rebuilt = Material::rebuilt(&p).unwrap();
            let mut sides = std::collections::HashSet::new();
            for i in 0..64 {
                let uv = Vec2::new((i as f32 * 0.37).fract(), (i as f32 * 0.61).fract());
                assert_eq!(m.at(uv), rebuilt.at(uv), "{xml} at {uv}");
                sides.insert(format!("{:?}", m.at(uv)));
            }
            assert!(sides.len() > 1, "the texture changes the model: {xml}");
        }
    }

    /// On a plane with ∂p/∂u = (2, 0, 0), ∂p/∂v = (0, 3, 0), a height gradient (a, b) gives the normal
    /// (2, 0, a) × (0, 3, b) ∝ (−3a, −2b, 6), in the shading frame and encoded as (n + 1)/2; turned to the
    /// geometric normal's side; the shading normal where there is no surface or no gradient.
    #[test]
    fn bump_normals_are_the_cross_product_of_the_bumped_partials() {
        let d = Differentials {
            n: Vec3::Z,
            shading: Frame::from_normal(Vec3::Z),
            dp_du: Vec3::new(2.0, 0.0, 0.0),
            dp_dv: Vec3::new(0.0, 3.0, 0.0),
            mesh: None,
            prim: 0,
            p: Vec3::ZERO,
        };
        let decode = |c: Rgb| Vec3::new(2.0 * c.r() - 1.0, 2.0 * c.g() - 1.0, 2.0 * c.b() - 1.0);
        for (a, b) in [(0.5f32, -1.0f32), (3.0, 2.0), (0.0, 0.0)] {
            let local = decode(bump_normal(Vec2::new(a, b), Some(&d)));
            let want = d.shading.to_local(Vec3::new(-3.0 * a, -2.0 * b, 6.0).normalize());
            assert!((local - want).length() < 1e-6, "({a}, {b}): {local} against {want}");
        }
        // ∂p/∂u × ∂p/∂v against the geometric normal: turned round.
        let flipped = Differentials { dp_dv: Vec3::new(0.0, -3.0, 0.0), ..d };
        assert!(decode(bump_normal(Vec2::new(0.5, -1.0), Some(&flipped))).z > 0.0);
        assert_eq!(bump_normal(Vec2::new(0.5, -1.0), None), Rgb::new(0.5, 0.5, 1.0));
    }
}
