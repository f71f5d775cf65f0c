//! A data set as WebDataset shards: a run's pictures, `size` at a time, each group packed
//! into one tar `set-IIIIII-SSSSSS.tar` (the run's shard I, its S-th tar) once every picture
//! of it is written whole, its files under the picture's key as the WebDataset convention
//! has it (`000042.png`, `000042.depth.exr`, `000042.json`, `000042.scene.ron`, …).
//!
//! A tar is written through a temporary file and renamed, its members in name order with
//! no time, owner or mode of the machine's, so the same pictures give the same bytes; the
//! pictures' loose files go once their tar is there. A run stopped and started again finds
//! the tars written whole and the pictures written loose, and renders only the others.

use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::generate::{GenerateError, Shard, manifest_line};

/// A run's tars: the folder, the shard it renders, the pictures a tar and the set's count.
#[derive(Debug, Clone, PartialEq)]
pub struct TarSet {
    pub dir: PathBuf,
    pub shard: Shard,
    pub size: usize,
    pub count: usize,
}

impl TarSet {
    /// The file of the run's `s`-th tar.
    fn tar_name(&self, s: usize) -> PathBuf {
        self.dir.join(format!("set-{:06}-{s:06}.tar", self.shard.index))
    }

    /// Each tar of the run and the pictures it holds: the shard's pictures, `size` at a time.
    pub fn tars(&self) -> Vec<(PathBuf, Vec<usize>)> {
        let pictures: Vec<usize> = self.shard.pictures(self.count).collect();
        pictures.chunks(self.size.max(1)).enumerate().map(|(s, group)| (self.tar_name(s), group.to_vec())).collect()
    }

    /// The tar that holds picture `k` and its pictures; none for a picture of another shard.
    pub fn tar_of(&self, k: usize) -> Option<(PathBuf, Vec<usize>)> {
        let Shard { index, count: shards } = self.shard;
        if k >= self.count || k % shards != index {
            return None;
        }
        let (size, in_shard) = (self.size.max(1), (self.count - index).div_ceil(shards));
        let s = (k / shards) / size;
        let group = (s * size..((s + 1) * size).min(in_shard)).map(|p| index + p * shards).collect();
        Some((self.tar_name(s), group))
    }

    /// The pictures the tars already written hold.
    pub fn packed(&self) -> BTreeSet<usize> {
        self.tars().into_iter().filter(|(tar, _)| tar.is_file()).flat_map(|(_, group)| group).collect()
    }

    /// Packs every tar not written yet whose pictures are all `finished` (written whole,
    /// loose in the folder). Returns how many it wrote.
    pub fn pack_finished(&self, finished: &BTreeSet<usize>) -> Result<usize, GenerateError> {
        let mut written = 0;
        for (tar, group) in self.tars() {
            written += usize::from(self.pack(&tar, &group, finished)?);
        }
        Ok(written)
    }

    /// Packs the tar that holds picture `k` once its pictures are all `finished`. Whether
    /// it wrote it.
    pub fn pack_tar_of(&self, k: usize, finished: &BTreeSet<usize>) -> Result<bool, GenerateError> {
        self.tar_of(k).map_or(Ok(false), |(tar, group)| self.pack(&tar, &group, finished))
    }

    /// Packs `group` into `tar` when the tar is not written yet and the pictures are all
    /// `finished`, then removes their loose files. Whether it wrote it.
    fn pack(&self, tar: &Path, group: &[usize], finished: &BTreeSet<usize>) -> Result<bool, GenerateError> {
        if tar.is_file() || !group.iter().all(|k| finished.contains(k)) {
            return Ok(false);
        }
        let files = group
            .iter()
            .map(|&k| Ok(manifest_line(&self.dir, k)?.files.into_iter().map(|(name, _)| name)))
            .collect::<Result<Vec<_>, GenerateError>>()?;
        let mut names: Vec<String> = files.into_iter().flatten().collect();
        names.sort();
        write_tar(&self.dir, &names, tar)?;
        for name in &names {
            let path = self.dir.join(name);
            std::fs::remove_file(&path).map_err(|source| GenerateError::Io { path, source })?;
        }
        Ok(true)
    }
}

/// Writes the files `names` of `dir` into the tar `path`, whole: through a temporary file,
/// synced, then renamed.
fn write_tar(dir: &Path, names: &[String], path: &Path) -> Result<(), GenerateError> {
    let io = |path: &Path| {
        let path = path.to_owned();
        move |source| GenerateError::Io { path, source }
    };
    let temporary = path.with_extension("tar.tmp");
    let file = std::fs::File::create(&temporary).map_err(io(&temporary))?;
    let mut builder = tar::Builder::new(std::io::BufWriter::new(file));
    for name in names {
        let member = dir.join(name);
        let bytes = std::fs::read(&member).map_err(io(&member))?;
        let mut header = tar::Header::new_gnu();
        header.set_path(name).map_err(io(&member))?;
        header.set_size(bytes.len() as u64);
        header.set_mode(0o644);
        header.set_mtime(0);
        header.set_uid(0);
        header.set_gid(0);
        header.set_entry_type(tar::EntryType::Regular);
        header.set_cksum();
        builder.append(&header, bytes.as_slice()).map_err(io(&temporary))?;
    }
    let mut out = builder.into_inner().map_err(io(&temporary))?;
    out.flush().map_err(io(&temporary))?;
    let file = out.into_inner().map_err(|e| GenerateError::Io { path: temporary.clone(), source: e.into_error() })?;
    file.sync_all().map_err(io(&temporary))?;
    std::fs::rename(&temporary, path).map_err(io(path))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tar of a picture is the one `tars` lists it in, for shards of every size.
    #[test]
    fn a_pictures_tar_is_the_one_that_lists_it() {
        for (index, count, size, pictures) in [(0, 1, 3, 8), (1, 3, 2, 11), (2, 3, 4, 11), (0, 4, 1000, 5)] {
            let set = TarSet { dir: PathBuf::from("d"), shard: Shard { index, count }, size, count: pictures };
            for (tar, group) in set.tars() {
                for &k in &group {
                    assert_eq!(set.tar_of(k), Some((tar.clone(), group.clone())), "{index}/{count} by {size}: {k}");
                }
            }
            let listed: BTreeSet<usize> = set.tars().into_iter().flat_map(|(_, g)| g).collect();
            assert!((0..pictures).filter(|k| !listed.contains(k)).all(|k| set.tar_of(k).is_none()));
        }
    }
}
