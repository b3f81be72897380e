//! Wavefront OBJ meshes (with their MTL materials) read through tobj.

use glam::{Vec2, Vec3};
use glint_lighting::PhongMaterial;
use glint_texture::{load_image, ImageTexture, Texture, TextureFilter, TextureImage, WrapMode};
use std::collections::HashMap;
use std::io::{BufRead, Read};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The most vertices, and the most triangles, an OBJ file may have.
pub const MAX_ELEMENTS: usize = 1 << 26;

/// One OBJ file as Glint uses it: all of its triangles in one list, the MTL
/// material each triangle uses (if any), and those materials as Phong materials.
pub struct ObjMesh {
    pub positions: Vec<Vec3>,
    /// Empty when the file has no normals (they are then generated).
    pub normals: Vec<Vec3>,
    /// Empty when the file has no texture coordinates.
    pub uvs: Vec<Vec2>,
    pub indices: Vec<[u32; 3]>,
    /// Per triangle: an index into `materials`, or `None`.
    pub triangle_materials: Vec<Option<u32>>,
    pub materials: Vec<(String, PhongMaterial)>,
    /// Every file read: the OBJ, the MTL files it names, the images they map.
    pub files: Vec<PathBuf>,
}

/// Reads `path`: polygons are triangulated (as fans), vertices de-duplicated per
/// (position, normal, uv) triple. MTL materials map to Phong: `Kd` → diffuse
/// (or `map_Kd`, an image relative to the OBJ, filtered trilinearly), `Ks` →
/// specular, `Ns` → shininess. Errors are one line naming the file.
pub fn load_obj(path: &Path, with_materials: bool) -> Result<ObjMesh, String> {
    load_obj_bounded(path, with_materials, FACES_PER_MODEL)
}

/// [`load_obj`], tobj given at most `faces_per_model` faces a model
/// ([`ModelsBounded`]).
fn load_obj_bounded(
    path: &Path,
    with_materials: bool,
    faces_per_model: usize,
) -> Result<ObjMesh, String> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let cannot_read =
        |e: &dyn std::fmt::Display| format!("{}: cannot read the OBJ file: {e}", path.display());
    // tobj reports a file it cannot open without the reason.
    crate::files::check_regular(path, crate::MAX_MESH_BYTES, "an OBJ file")
        .map_err(|e| cannot_read(&e))?;
    let file = std::fs::File::open(path).map_err(|e| cannot_read(&e))?;
    check_face_indices(path)?;
    let base = path.parent().unwrap_or(Path::new(""));
    // The MTL materials are read only without a scene material; then a
    // material library the OBJ names must be there and parse, and one tobj
    // would panic on is refused first (the loader is `Fn`: the reason is kept
    // in a cell).
    let refused = std::cell::RefCell::new(None);
    let mut reader = ModelsBounded::new(std::io::BufReader::new(file), faces_per_model);
    let (models, materials) = tobj::load_obj_buf(&mut reader, &options, |library| {
        if !with_materials {
            return Ok(Default::default());
        }
        let library = base.join(library);
        if let Err(e) = check_material_library(&library) {
            *refused.borrow_mut() = Some(e);
            return Err(tobj::LoadError::MaterialParseError);
        }
        tobj::load_mtl(library)
    })
    .map_err(|e| cannot_read(&e))?;
    if let Some(why) = refused.into_inner() {
        return Err(format!(
            "{}: cannot read its material library {why}",
            path.display()
        ));
    }
    let materials = materials.map_err(|e| material_library_error(path, e))?;
    // MTL images are read only when the scene uses the MTL materials, each once.
    let mut images = HashMap::new();
    let phong = if with_materials {
        materials
            .iter()
            .map(|m| Ok((m.name.clone(), mtl_to_phong(m, base, &mut images)?)))
            .collect::<Result<Vec<_>, String>>()?
    } else {
        Vec::new()
    };

    let mut mesh = ObjMesh {
        positions: Vec::new(),
        normals: Vec::new(),
        uvs: Vec::new(),
        indices: Vec::new(),
        triangle_materials: Vec::new(),
        materials: phong,
        files: std::iter::once(path.to_owned())
            .chain(
                with_materials
                    .then(|| material_libraries(path))
                    .into_iter()
                    .flatten(),
            )
            .chain(images.into_keys())
            .collect(),
    };
    // Normals and uvs are kept only if every vertex of every object has them (an
    // OBJ may give them to some faces only); otherwise normals are generated.
    let all_have = |f: fn(&tobj::Mesh) -> bool| models.iter().all(|m| f(&m.mesh));
    let keep_normals = all_have(|m| m.normals.len() == m.positions.len());
    let keep_uvs = all_have(|m| m.texcoords.len() / 2 == m.positions.len() / 3);
    let vertices: usize = models.iter().map(|m| m.mesh.positions.len() / 3).sum();
    let triangles: usize = models.iter().map(|m| m.mesh.indices.len() / 3).sum();
    if vertices > MAX_ELEMENTS || triangles > MAX_ELEMENTS {
        return Err(format!(
            "{}: {vertices} vertices and {triangles} triangles, more than the limit of {MAX_ELEMENTS}",
            path.display()
        ));
    }
    mesh.positions.reserve_exact(vertices);
    mesh.normals
        .reserve_exact(if keep_normals { vertices } else { 0 });
    mesh.uvs.reserve_exact(if keep_uvs { vertices } else { 0 });
    mesh.indices.reserve_exact(triangles);
    mesh.triangle_materials.reserve_exact(triangles);
    // Each model is dropped once copied: tobj's copy and this one are not
    // both held whole.
    for model in models {
        let m = &model.mesh;
        let first = mesh.positions.len() as u32;
        let vertices = m.positions.len() / 3;
        mesh.positions.extend(
            m.positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        if keep_normals {
            mesh.normals.extend(
                m.normals
                    .chunks_exact(3)
                    .map(|n| Vec3::new(n[0], n[1], n[2])),
            );
        }
        if keep_uvs {
            mesh.uvs
                .extend(m.texcoords.chunks_exact(2).map(|t| Vec2::new(t[0], t[1])));
        }
        for tri in m.indices.chunks_exact(3) {
            if let Some(&bad) = tri.iter().find(|&&i| i as usize >= vertices) {
                return Err(format!(
                    "{}: object \"{}\" refers to vertex {bad}, but it has only {vertices}",
                    path.display(),
                    model.name
                ));
            }
            mesh.indices
                .push([tri[0] + first, tri[1] + first, tri[2] + first]);
            let material = m
                .material_id
                .filter(|&id| id < mesh.materials.len())
                .map(|id| id as u32);
            mesh.triangle_materials.push(material);
        }
    }
    if mesh.indices.is_empty() {
        return Err(format!("{}: the OBJ file has no faces", path.display()));
    }
    Ok(mesh)
}

/// The faces of one model tobj is given at most: it holds a model's faces
/// (about 100 bytes each, in a list grown by doubling) until the model ends.
const FACES_PER_MODEL: usize = 1 << 16;

/// An OBJ file as tobj reads it, with the current object or group line (the
/// last `o` or `g` line, or tobj's default name before one) said again before
/// every `limit`-th face of a model, where tobj then ends the model and starts
/// another of the same name and material. The triangles, their order, their
/// corners and their materials are the file's; a vertex used on both sides of
/// such a break is stored once on each (tobj gathers vertices per model).
struct ModelsBounded<R> {
    inner: R,
    /// What is served: the next line of the file, after a group line said again.
    served: Vec<u8>,
    at: usize,
    /// The last `o` or `g` line, with its line end.
    group: Vec<u8>,
    faces: usize,
    limit: usize,
}

impl<R: BufRead> ModelsBounded<R> {
    fn new(inner: R, limit: usize) -> Self {
        Self {
            inner,
            served: Vec::new(),
            at: 0,
            group: b"g unnamed_object\n".to_vec(),
            faces: 0,
            limit,
        }
    }

    /// Reads the file's next line into `served`, the group line before it
    /// where a model has `limit` faces already.
    fn next_line(&mut self) -> std::io::Result<()> {
        self.served.clear();
        self.at = 0;
        self.inner.read_until(b'\n', &mut self.served)?;
        // tobj's first word: of the line as UTF-8 (one that is not fails tobj).
        let first = std::str::from_utf8(&self.served)
            .ok()
            .and_then(|l| l.split_whitespace().next());
        match first {
            Some("o" | "g") => {
                self.group.clone_from(&self.served);
                if !self.group.ends_with(b"\n") {
                    self.group.push(b'\n');
                }
                self.faces = 0;
            }
            Some("f") if self.faces == self.limit => {
                self.served.splice(0..0, self.group.iter().copied());
                self.faces = 1;
            }
            Some("f") => self.faces += 1,
            _ => {}
        }
        Ok(())
    }
}

impl<R: BufRead> Read for ModelsBounded<R> {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        let available = self.fill_buf()?;
        let n = available.len().min(out.len());
        out[..n].copy_from_slice(&available[..n]);
        self.consume(n);
        Ok(n)
    }
}

impl<R: BufRead> BufRead for ModelsBounded<R> {
    fn fill_buf(&mut self) -> std::io::Result<&[u8]> {
        if self.at == self.served.len() {
            self.next_line()?;
        }
        Ok(&self.served[self.at..])
    }

    fn consume(&mut self, n: usize) {
        self.at += n;
    }
}

/// Why the material libraries of the OBJ at `path` could not be read: the
/// first one missing or unreadable by name, else tobj's parse error `e`, with
/// what the user can do about it.
fn material_library_error(path: &Path, e: tobj::LoadError) -> String {
    let base = path.parent().unwrap_or(Path::new(""));
    let named = library_names(path);
    let unreadable = named.iter().find_map(|name| {
        std::fs::read(base.join(name))
            .err()
            .map(|io| format!("{name}: {io}"))
    });
    let why = unreadable.unwrap_or_else(|| format!("{}: {e}", named.join(", ")));
    format!(
        "{}: cannot read its material library {why} (give the mesh a `material` to render it without)",
        path.display()
    )
}

/// Refuses a face index that tobj 4 would overflow on when it scales it to an
/// array offset (a relative index before the first element, or one beyond
/// 2⁴⁰), naming the line; tobj reports the other bad indices itself. Normals
/// that are not directions are refused too ([`check_normal`]).
fn check_face_indices(path: &Path) -> Result<(), String> {
    let Ok(bytes) = std::fs::read(path) else {
        return Ok(()); // tobj reports it
    };
    // Elements so far: positions, texture coordinates, normals.
    let mut counts = [0i64; 3];
    for (number, line) in String::from_utf8_lossy(&bytes).lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => counts[0] += 1,
            Some("vt") => counts[1] += 1,
            Some("vn") => {
                counts[2] += 1;
                check_normal(words, counts[2])
                    .map_err(|why| format!("{}: line {}: {why}", path.display(), number + 1))?;
            }
            Some("f") => {
                for (kind, index) in words.flat_map(|w| w.split('/').enumerate()) {
                    let (Ok(index), Some(&count)) = (index.parse::<i64>(), counts.get(kind)) else {
                        continue;
                    };
                    if count + index < 0 || index > 1 << 40 {
                        return Err(format!(
                            "{}: line {}: face index {index} is out of range",
                            path.display(),
                            number + 1
                        ));
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// A `vn` line's three numbers must make a direction: finite and not all zero
/// (a NaN normal would shade its triangles NaN, silently dropped).
fn check_normal<'a>(words: impl Iterator<Item = &'a str>, index: i64) -> Result<(), String> {
    let values: Vec<f32> = words.take(3).filter_map(|w| w.parse().ok()).collect();
    match values[..] {
        [x, y, z] if [x, y, z].iter().all(|v| v.is_finite()) && (x, y, z) != (0.0, 0.0, 0.0) => {
            Ok(())
        }
        [_, _, _] => Err(format!(
            "normal {index} is {values:?}; expected three finite numbers, not all 0"
        )),
        _ => Ok(()), // tobj reports a short line
    }
}

/// Refuses a colour line (`Ka`, `Kd`, `Ks`, `Ke`) with fewer than three values
/// in the material library at `library`, naming the file and line: tobj 4
/// panics on one (it unwraps a three-element conversion).
fn check_material_library(library: &Path) -> Result<(), String> {
    if library.exists() {
        crate::files::check_regular(library, crate::MAX_MESH_BYTES, "an MTL file")
            .map_err(|e| format!("{}: {e}", library.display()))?;
    }
    let Ok(bytes) = std::fs::read(library) else {
        return Ok(()); // tobj reports it
    };
    // tobj reads line by line: the lines before a bad byte still count.
    for (number, line) in String::from_utf8_lossy(&bytes).lines().enumerate() {
        let mut words = line.split_whitespace();
        let key = words.next();
        if matches!(key, Some("Ka" | "Kd" | "Ks" | "Ke")) && words.count() < 3 {
            return Err(format!(
                "{}: line {}: `{}` needs three numbers (r g b)",
                library.display(),
                number + 1,
                key.unwrap_or_default()
            ));
        }
    }
    Ok(())
}

/// The names of the MTL files an OBJ names on its `mtllib` lines.
fn library_names(path: &Path) -> Vec<String> {
    let Ok(bytes) = std::fs::read(path) else {
        return Vec::new();
    };
    // As tobj reads them: the rest of the line is one name, spaces and all.
    String::from_utf8_lossy(&bytes)
        .lines()
        .map(str::trim)
        .filter(|l| l.split_whitespace().next() == Some("mtllib"))
        .map(|l| l.split_once(' ').unwrap_or_default().1.trim().to_owned())
        .collect()
}

/// The MTL files an OBJ names (`mtllib` lines, relative to the OBJ) that exist.
fn material_libraries(path: &Path) -> Vec<PathBuf> {
    let base = path.parent().unwrap_or(Path::new(""));
    library_names(path)
        .into_iter()
        .map(|name| base.join(name))
        .filter(|p| p.is_file())
        .collect()
}

fn mtl_to_phong(
    m: &tobj::Material,
    base: &Path,
    images: &mut HashMap<PathBuf, Arc<TextureImage>>,
) -> Result<PhongMaterial, String> {
    let color = |c: Option<[f32; 3]>, default: Vec3| {
        c.map(Vec3::from_array).unwrap_or(default).max(Vec3::ZERO)
    };
    let kd = color(m.diffuse, Vec3::splat(0.8));
    let diffuse = match &m.diffuse_texture {
        Some(file) => {
            let path = base.join(file);
            let image = match images.get(&path) {
                Some(image) => image.clone(),
                None => {
                    let loaded =
                        load_image(&path).map_err(|e| format!("material \"{}\": {e}", m.name))?;
                    let image = TextureImage::new(loaded);
                    images.insert(path, image.clone());
                    image
                }
            };
            // As in most renderers, map_Kd replaces Kd (rather than scaling it).
            Texture::Image(ImageTexture::new(
                image,
                WrapMode::Repeat,
                TextureFilter::Trilinear,
            ))
        }
        None => Texture::Constant(kd),
    };
    let shininess = m
        .shininess
        .filter(|s| s.is_finite() && *s >= 0.0)
        .unwrap_or(1.0);
    Ok(PhongMaterial {
        diffuse,
        specular: Some(Texture::Constant(color(m.specular, Vec3::ZERO))),
        ..PhongMaterial::new(Vec3::ZERO, shininess)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_polygons_materials_and_reports_bad_files() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("quad.mtl"),
            "newmtl red\nKd 0.8 0.1 0.1\nKs 0.2 0.2 0.2\nNs 30\n",
        )
        .unwrap();
        let obj = dir.path().join("quad.obj");
        std::fs::write(
            &obj,
            "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nusemtl red\nf 1 2 3 4\nf 1 2 5\n",
        )
        .unwrap();
        let mesh = load_obj(&obj, true).unwrap();
        assert_eq!(mesh.indices.len(), 3, "a quad is two triangles, plus one");
        assert!(mesh.normals.is_empty() && mesh.uvs.is_empty());
        assert_eq!(mesh.materials.len(), 1);
        let (name, red) = &mesh.materials[0];
        assert_eq!(name, "red");
        assert_eq!(red.diffuse, Texture::Constant(Vec3::new(0.8, 0.1, 0.1)));
        assert_eq!(red.shininess, 30.0);
        assert!(mesh.triangle_materials.iter().all(|m| *m == Some(0)));

        // Normals on some faces only: dropped (and generated later), not an error.
        let partial = dir.path().join("partial.obj");
        std::fs::write(
            &partial,
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\nf 2 4 3\n",
        )
        .unwrap();
        let p = load_obj(&partial, true).unwrap();
        assert_eq!(p.indices.len(), 2);
        assert!(p.normals.is_empty());

        let missing = load_obj(&dir.path().join("nope.obj"), true).err().unwrap();
        assert!(
            missing.contains("nope.obj: cannot read the OBJ file"),
            "{missing}"
        );
        let empty = dir.path().join("empty.obj");
        std::fs::write(&empty, "v 0 0 0\nv 1 0 0\n").unwrap();
        assert!(load_obj(&empty, true)
            .err()
            .unwrap()
            .contains("has no faces"));
        let bad = dir.path().join("bad.obj");
        std::fs::write(&bad, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n").unwrap();
        assert!(load_obj(&bad, true).is_err());
        // A material library that is missing or does not parse: an error when
        // the MTL materials are used, not read at all when they are not.
        let lost = dir.path().join("lost.obj");
        let faces = "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n";
        std::fs::write(&lost, format!("mtllib gone.mtl\n{faces}")).unwrap();
        let e = load_obj(&lost, true).err().unwrap();
        assert!(
            e.contains("lost.obj: cannot read its material library gone.mtl: "),
            "{e}"
        );
        assert_eq!(load_obj(&lost, false).unwrap().indices.len(), 1);
        // An OBJ `NAME.obj` of one red triangle whose library `NAME.mtl` is `mtl`.
        let with_library = |name: &str, mtl: &str| {
            std::fs::write(dir.path().join(format!("{name}.mtl")), mtl).unwrap();
            let obj = dir.path().join(format!("{name}.obj"));
            std::fs::write(&obj, format!("mtllib {name}.mtl\n{faces}")).unwrap();
            obj
        };
        let broken = with_library("broken", "newmtl red\nKd 1 x 0\n");
        let e = load_obj(&broken, true).err().unwrap();
        assert!(
            e.contains("material library broken.mtl: material parse error"),
            "{e}"
        );
        assert!(load_obj(&broken, false).is_ok());
        // Face indices tobj 4 would overflow on: refused by line.
        for face in [
            "f 1 2 -9",
            "f 1/-2 2/1 3/1",
            "f 1//99999999999999999 2//1 3//1",
        ] {
            let far = dir.path().join("far.obj");
            std::fs::write(
                &far,
                format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n{face}\n"),
            )
            .unwrap();
            let e = load_obj(&far, false).err().unwrap();
            assert!(e.contains("far.obj: line 6: face index"), "{face}: {e}");
        }
        // A colour with one value (tobj 4 would panic on it): refused by line.
        let short = with_library("short", "newmtl red\n\nKs 60\n");
        let e = load_obj(&short, true).err().unwrap();
        assert!(
            e.contains("short.mtl: line 3: `Ks` needs three numbers"),
            "{e}"
        );
        assert!(load_obj(&short, false).is_ok());
    }

    /// Each triangle's corners (position, normal, uv) and material.
    fn corners(mesh: &ObjMesh) -> Vec<([[f32; 8]; 3], Option<u32>)> {
        let corner = |v: u32| {
            let (v, p) = (v as usize, mesh.positions[v as usize]);
            let n = mesh.normals.get(v).copied().unwrap_or_default();
            let t = mesh.uvs.get(v).copied().unwrap_or_default();
            [p.x, p.y, p.z, n.x, n.y, n.z, t.x, t.y]
        };
        let triangles = mesh.indices.iter().map(|tri| tri.map(corner));
        triangles
            .zip(mesh.triangle_materials.iter().copied())
            .collect()
    }

    #[test]
    fn models_ended_every_few_faces_give_the_same_triangles() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("two.mtl"),
            "newmtl red\nKd 0.8 0.1 0.1\nnewmtl blue\nKd 0.1 0.1 0.8\n",
        )
        .unwrap();
        let grid = |z: f32| {
            let mut s = String::new();
            for j in 0..3 {
                for i in 0..3 {
                    s += &format!(
                        "v {i} {j} {z}\nvt {} {}\nvn 0 0.{} 1\n",
                        i as f32 / 2.0,
                        j as f32 / 2.0,
                        i + j
                    );
                }
            }
            s
        };
        // Two objects of shared vertices, a material switch inside one,
        // quads (two triangles each), a pentagon and negative indices; the
        // first faces come before any `o` line.
        let obj = format!(
            "mtllib two.mtl\n{}{}f 1/1/1 2/2/2 5/5/5\no first part\nusemtl red\n\
             f 1/1/1 2/2/2 5/5/5 4/4/4\nf 2/2/2 3/3/3 6/6/6 5/5/5\nf 4/4/4 5/5/5 8/8/8 7/7/7\n\
             usemtl blue\nf 5/5/5 6/6/6 9/9/9 8/8/8\nf 1/1/1 3/3/3 9/9/9 8/8/8 7/7/7\n\
             g second\nf -1/-1/-1 -2/-2/-2 -5/-5/-5\nf 10/10/10 11/11/11 14/14/14 13/13/13\n\
             f 11/11/11 12/12/12 15/15/15 14/14/14\nf 13/13/13 14/14/14 17/17/17\n",
            grid(0.0),
            grid(1.0)
        );
        let path = dir.path().join("parts.obj");
        std::fs::write(&path, &obj).unwrap();
        let whole = load_obj_bounded(&path, true, usize::MAX).unwrap();
        assert_eq!(whole.indices.len(), 18);
        for limit in [1, 2, 3] {
            let bounded = load_obj_bounded(&path, true, limit).unwrap();
            assert_eq!(corners(&bounded), corners(&whole), "{limit} faces a model");
            assert!(bounded.positions.len() > whole.positions.len(), "{limit}");
        }
        // Windows line ends, and a last line without one: the same triangles.
        let crlf = dir.path().join("crlf.obj");
        let windows = obj.replace('\n', "\r\n");
        std::fs::write(&crlf, windows.trim_end()).unwrap();
        for limit in [1, 2, usize::MAX] {
            let bounded = load_obj_bounded(&crlf, true, limit).unwrap();
            assert_eq!(
                corners(&bounded),
                corners(&whole),
                "CRLF, {limit} faces a model"
            );
        }
    }
}
