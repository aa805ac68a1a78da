//! Output folders written all or nothing: the folder is checked before the long work
//! starts, every file is written under a temporary name beside its final one, and only
//! when all of them are written are they renamed into place. A run that fails half-way
//! leaves the previous outputs as they were, never a mixture. And what a rendered
//! output's name asks for ([`render_target`]).

use std::path::{Path, PathBuf};

use crate::{Error, Result};

/// Makes sure `dir` is (or can be made) a folder this process can write into. Called
/// before a run starts, so that a bad `--out` is reported at once, not after the work.
pub fn prepare_dir(dir: &Path) -> Result<()> {
    prepare_dir_for(dir, "--out")
}

/// [`prepare_dir`] for the folder that `flag` names.
pub fn prepare_dir_for(dir: &Path, flag: &str) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        return Err(Error::output(
            dir,
            format!("exists and is not a folder; {flag} names a folder for the output files"),
        ));
    }
    std::fs::create_dir_all(dir)
        .map_err(|e| Error::output(dir, format!("cannot create the folder: {e}")))?;
    let probe = dir.join(format!(".slidebase-write-test-{}", std::process::id()));
    std::fs::write(&probe, b"")
        .map_err(|e| Error::output(dir, format!("cannot write into the folder: {e}")))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// [`prepare_dir_for`], and none of the files `names` the work will write into `dir` is a
/// folder there (it could not be replaced, and the run would fail only at its end).
pub fn prepare_outputs(dir: &Path, flag: &str, names: &[&str]) -> Result<()> {
    prepare_dir_for(dir, flag)?;
    match names.iter().map(|n| dir.join(n)).find(|p| p.is_dir()) {
        Some(blocked) => Err(Error::output(
            &blocked,
            format!("is a folder; {flag} names a folder whose output files would replace it"),
        )),
        None => Ok(()),
    }
}

/// Makes sure the file `path` (named by `flag`) can be written: its folder is (or can be
/// made) a writable folder and the path itself is not a folder. Checked before the work
/// that produces the file, as [`prepare_dir`] is.
pub fn prepare_file_for(path: &Path, flag: &str) -> Result<()> {
    if path.is_dir() {
        return Err(Error::output(
            path,
            format!("is a folder; {flag} names the file to write"),
        ));
    }
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if folder.exists() && !folder.is_dir() {
        return Err(Error::output(
            folder,
            format!(
                "is not a folder, so {flag} {} cannot be written in it",
                path.display()
            ),
        ));
    }
    prepare_dir_for(folder, flag)
}

/// The video formats a replay is written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VideoFormat {
    /// H.264 in MP4, through ffmpeg.
    Mp4,
    /// Animated GIF.
    Gif,
}

/// What `render --out path` writes, by the name's extension (any case): a picture
/// (`None`) for `.png`, a replay in a [`VideoFormat`] for `.mp4` or `.gif`. Any other
/// name is refused before anything is computed: it would get a PNG's bytes. (Checked
/// here, outside the renderer, so that a build without the window refuses it too.)
pub fn render_target(path: &Path) -> Result<Option<VideoFormat>> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_lowercase);
    match extension.as_deref() {
        Some("png") => Ok(None),
        Some("mp4") => Ok(Some(VideoFormat::Mp4)),
        Some("gif") => Ok(Some(VideoFormat::Gif)),
        _ => Err(Error::invalid(
            "--out",
            format!(
                "{}: give a .png (a picture), or an .mp4 or .gif (a replay)",
                path.display()
            ),
        )),
    }
}

/// A set of files being written into one folder.
#[derive(Debug)]
pub struct Staged {
    dir: PathBuf,
    files: Vec<(PathBuf, PathBuf)>,
    committed: bool,
}

impl Staged {
    /// Starts writing into `dir` (checked and created by [`prepare_dir`]).
    pub fn new(dir: &Path) -> Result<Self> {
        prepare_dir(dir)?;
        Ok(Self {
            dir: dir.to_path_buf(),
            files: Vec::new(),
            committed: false,
        })
    }

    /// The temporary path to write the file `name` to (its extension kept, so that
    /// writers that go by it still work).
    pub fn path(&mut self, name: &str) -> PathBuf {
        let tmp = self
            .dir
            .join(format!(".partial-{}-{name}", std::process::id()));
        self.files.push((tmp.clone(), self.dir.join(name)));
        tmp
    }

    /// Writes `contents` as the file `name`.
    pub fn write(&mut self, name: &str, contents: impl AsRef<[u8]>) -> Result<()> {
        let path = self.path(name);
        std::fs::write(&path, contents).map_err(|e| Error::io(self.dir.join(name), e))
    }

    /// Writes `rows` as the CSV table `name` (header from the field names).
    pub fn write_csv<T: serde::Serialize>(&mut self, name: &str, rows: &[T]) -> Result<()> {
        let path = self.path(name);
        let target = self.dir.join(name);
        let csv_error = |e: csv::Error| Error::output(&target, format!("cannot write: {e}"));
        let mut w = csv::Writer::from_path(&path).map_err(csv_error)?;
        for r in rows {
            w.serialize(r).map_err(csv_error)?;
        }
        w.flush().map_err(|e| Error::io(&target, e))
    }

    /// Writes `value` as the pretty-printed JSON file `name`.
    pub fn write_json<T: serde::Serialize>(&mut self, name: &str, value: &T) -> Result<()> {
        let text = serde_json::to_string_pretty(value)
            .map_err(|e| Error::output(self.dir.join(name), format!("cannot serialise: {e}")))?;
        self.write(name, text)
    }

    /// Moves every written file into place; returns the final paths.
    pub fn commit(mut self) -> Result<Vec<PathBuf>> {
        // A rename onto a folder would fail half-way through: check them all first (a
        // rename onto a file replaces it whole).
        if let Some((_, target)) = self.files.iter().find(|(_, t)| t.is_dir()) {
            return Err(Error::output(
                target,
                "is a folder; it cannot be replaced by an output file",
            ));
        }
        for (tmp, target) in &self.files {
            std::fs::rename(tmp, target).map_err(|e| Error::io(target, e))?;
        }
        self.committed = true;
        Ok(self.files.iter().map(|(_, t)| t.clone()).collect())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.committed {
            for (tmp, _) in &self.files {
                let _ = std::fs::remove_file(tmp);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Files appear only on commit; an abandoned set leaves nothing behind.
    #[test]
    fn files_appear_all_at_once() {
        let dir = std::env::temp_dir().join(format!("slidebase-staged-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        {
            let mut s = Staged::new(&dir).unwrap_or_else(|e| panic!("{e}"));
            s.write("a.txt", "a").unwrap_or_else(|e| panic!("{e}"));
            assert!(!dir.join("a.txt").exists());
        }
        assert_eq!(std::fs::read_dir(&dir).map(|d| d.count()).unwrap_or(99), 0);
        let mut s = Staged::new(&dir).unwrap_or_else(|e| panic!("{e}"));
        s.write("a.txt", "a").unwrap_or_else(|e| panic!("{e}"));
        s.write("b.txt", "b").unwrap_or_else(|e| panic!("{e}"));
        let files = s.commit().unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(files.len(), 2);
        assert!(dir.join("a.txt").exists() && dir.join("b.txt").exists());
        let file = dir.join("a.txt");
        assert!(matches!(prepare_dir(&file), Err(Error::Output { .. })));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
