//! Video in and out through the `ffmpeg` and `ffprobe` programs (issue 18: "frames from an image
//! folder or from a video decoded by `ffmpeg`", "a video through `ffmpeg` when asked"). No codec
//! crate decodes and encodes the formats cameras and players use as well as ffmpeg does, so
//! iblkit runs it as a child process and streams raw frames through a pipe, one frame in memory
//! at a time.
//!
//! **Decoding** ([`VideoReader`]): `ffmpeg -i VIDEO -f rawvideo -pix_fmt rgb48le -`, 16 bits
//! per channel, read as the sRGB-encoded values a video holds and made linear with the sRGB EOTF
//! (IEC 61966-2-1). A video is display-referred: the linear values are the camera's, up to its
//! unknown exposure and tone curve, so the estimates of a video are in its units, not in the
//! probe's (calibrate the camera, or give HDR frames as images, for radiometric estimates).
//!
//! **Encoding** ([`VideoWriter`]): tone-mapped 8-bit frames piped as `rawvideo rgb24` into
//! `ffmpeg`, H.264 where ffmpeg has it (the format follows the file's extension), `yuv420p` for
//! players, frames padded to even sizes. The file is written under a hidden name beside the
//! output and renamed when ffmpeg has finished, so a failed or interrupted run never leaves a
//! half-written video under the name asked for.

use std::io::{BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};

use ibl_core::tonemap::srgb_to_linear;
use ibl_core::{Image, Rgb};

use crate::error::{PipelineError, Result};

/// Largest frame side accepted from a video, pixels.
pub const MAX_VIDEO_SIDE: u32 = 16384;
/// Largest frame accepted from a video, pixels.
pub const MAX_VIDEO_PIXELS: u64 = 1 << 26;

fn missing_tool(tool: &str, e: std::io::Error) -> PipelineError {
    PipelineError::parameter(format!(
        "cannot run {tool} ({e}): video input and --video need ffmpeg and ffprobe on the PATH \
         (Debian/Ubuntu: apt install ffmpeg)"
    ))
}

/// The size of the first video stream of `path`, through `ffprobe`.
pub fn video_size(path: &Path) -> Result<(u32, u32)> {
    let out = Command::new("ffprobe")
        .args([
            "-v",
            "error",
            "-select_streams",
            "v:0",
            "-show_entries",
            "stream=width,height",
            "-of",
            "csv=p=0:s=x",
        ])
        .arg(path)
        .stdin(Stdio::null())
        .output()
        .map_err(|e| missing_tool("ffprobe", e))?;
    let shown = path.display();
    if !out.status.success() {
        return Err(PipelineError::parameter(format!(
            "{shown}: ffprobe cannot read it as a video: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        )));
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let size = text.lines().next().and_then(|l| {
        let (w, h) = l.trim().split_once('x')?;
        Some((w.parse::<u32>().ok()?, h.parse::<u32>().ok()?))
    });
    match size {
        Some((w, h))
            if (1..=MAX_VIDEO_SIDE).contains(&w)
                && (1..=MAX_VIDEO_SIDE).contains(&h)
                && u64::from(w) * u64::from(h) <= MAX_VIDEO_PIXELS =>
        {
            Ok((w, h))
        }
        Some((w, h)) => Err(PipelineError::parameter(format!(
            "{shown}: {w} x {h} frames, over the limit of {MAX_VIDEO_SIDE} per side and {MAX_VIDEO_PIXELS} pixels"
        ))),
        None => Err(PipelineError::parameter(format!(
            "{shown}: no video stream (ffprobe said {:?})",
            text.trim()
        ))),
    }
}

/// The frames of a video, decoded one at a time.
pub struct VideoReader {
    path: PathBuf,
    child: Child,
    stdout: BufReader<ChildStdout>,
    size: (u32, u32),
    buffer: Vec<u8>,
}

impl VideoReader {
    /// Starts decoding `path` (its size from [`video_size`]).
    pub fn open(path: &Path) -> Result<VideoReader> {
        let size = video_size(path)?;
        let mut child = Command::new("ffmpeg")
            .args(["-v", "error", "-nostdin", "-i"])
            .arg(path)
            .args(["-f", "rawvideo", "-pix_fmt", "rgb48le", "-"])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| missing_tool("ffmpeg", e))?;
        let stdout = child
            .stdout
            .take()
            .map(BufReader::new)
            .ok_or_else(|| PipelineError::parameter("ffmpeg gave no output pipe"))?;
        let bytes = size.0 as usize * size.1 as usize * 6;
        Ok(VideoReader {
            path: path.to_path_buf(),
            child,
            stdout,
            size,
            buffer: vec![0; bytes],
        })
    }

    /// Frame size, pixels.
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// The next frame as linear RGB (see the module notes), or `None` at the end of the video.
    pub fn next_frame(&mut self) -> Result<Option<Image<Rgb>>> {
        let mut filled = 0;
        while filled < self.buffer.len() {
            match self.stdout.read(&mut self.buffer[filled..]) {
                Ok(0) => break,
                Ok(n) => filled += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => {
                    return Err(PipelineError::parameter(format!(
                        "{}: reading ffmpeg's frames: {e}",
                        self.path.display()
                    )));
                }
            }
        }
        if filled == 0 {
            return self.finish().map(|()| None);
        }
        if filled < self.buffer.len() {
            return Err(PipelineError::parameter(format!(
                "{}: the video ended inside a frame ({filled} of {} bytes)",
                self.path.display(),
                self.buffer.len()
            )));
        }
        let (w, h) = (self.size.0 as usize, self.size.1 as usize);
        let channel = |k: usize| {
            let v = u16::from_le_bytes([self.buffer[2 * k], self.buffer[2 * k + 1]]);
            srgb_to_linear(f32::from(v) / 65535.0)
        };
        let pixels = (0..w * h)
            .map(|p| Rgb::new(channel(3 * p), channel(3 * p + 1), channel(3 * p + 2)))
            .collect();
        Image::from_vec(w, h, pixels)
            .map(Some)
            .map_err(|e| PipelineError::parameter(format!("{}: {e}", self.path.display())))
    }

    /// Waits for ffmpeg and reports its failure, if any.
    fn finish(&mut self) -> Result<()> {
        let status = self.child.wait().map_err(|e| missing_tool("ffmpeg", e))?;
        if status.success() {
            return Ok(());
        }
        let mut err = String::new();
        if let Some(mut e) = self.child.stderr.take() {
            let _ = e.read_to_string(&mut err);
        }
        Err(PipelineError::parameter(format!(
            "{}: ffmpeg could not decode it: {}",
            self.path.display(),
            err.trim()
        )))
    }
}

impl Drop for VideoReader {
    fn drop(&mut self) {
        // Stopped early (--frames): do not leave ffmpeg running.
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A video being written from 8-bit frames.
pub struct VideoWriter {
    path: PathBuf,
    temporary: PathBuf,
    /// Lists the temporary file for removal on an interrupt (`ibl_io::temp_files`).
    _listed: ibl_io::temp_files::TempRegistration,
    child: Child,
    stdin: Option<ChildStdin>,
    size: (usize, usize),
}

impl VideoWriter {
    /// Starts writing `path` (its container from the extension) with frames of `size` at `fps`.
    pub fn create(path: &Path, size: (usize, usize), fps: f64) -> Result<VideoWriter> {
        let folder = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_else(|| "video.mp4".into());
        ibl_io::temp_files::clean_stale_in(&folder);
        let temporary = folder.join(format!("{}{name}", ibl_io::temp_files::temp_prefix()));
        let listed = ibl_io::temp_files::TempRegistration::new(&temporary);
        let mut child = Command::new("ffmpeg")
            .args([
                "-v", "error", "-nostdin", "-y", "-f", "rawvideo", "-pix_fmt", "rgb24",
            ])
            .args(["-s", &format!("{}x{}", size.0, size.1)])
            .args(["-r", &format!("{fps}"), "-i", "-"])
            .args([
                "-vf",
                "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                "-pix_fmt",
                "yuv420p",
            ])
            .arg(&temporary)
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| missing_tool("ffmpeg", e))?;
        let stdin = child.stdin.take();
        Ok(VideoWriter {
            path: path.to_path_buf(),
            temporary,
            _listed: listed,
            child,
            stdin,
            size,
        })
    }

    /// Appends one frame (sRGB-encoded, `size` pixels).
    pub fn push(&mut self, frame: &Image<[u8; 3]>) -> Result<()> {
        if (frame.width(), frame.height()) != self.size {
            return Err(PipelineError::parameter(format!(
                "{}: a {} x {} frame in a {} x {} video",
                self.path.display(),
                frame.width(),
                frame.height(),
                self.size.0,
                self.size.1
            )));
        }
        let bytes: Vec<u8> = frame.pixels().iter().flatten().copied().collect();
        let written = match self.stdin.as_mut() {
            Some(stdin) => stdin.write_all(&bytes),
            None => Err(std::io::Error::other("no input pipe")),
        };
        written.map_err(|e| self.failed(&e.to_string()))
    }

    /// Ends the video: waits for ffmpeg and puts the file in place.
    pub fn finish(mut self) -> Result<PathBuf> {
        drop(self.stdin.take());
        let status = self.child.wait().map_err(|e| missing_tool("ffmpeg", e))?;
        if !status.success() {
            return Err(self.failed("ffmpeg failed"));
        }
        std::fs::rename(&self.temporary, &self.path).map_err(|e| {
            PipelineError::parameter(format!(
                "{}: cannot put the video in place: {e}",
                self.path.display()
            ))
        })?;
        Ok(self.path.clone())
    }

    /// The error of a failed write, with ffmpeg's message, the temporary file removed.
    fn failed(&mut self, what: &str) -> PipelineError {
        drop(self.stdin.take());
        let _ = self.child.wait();
        let mut err = String::new();
        if let Some(mut e) = self.child.stderr.take() {
            let _ = e.read_to_string(&mut err);
        }
        let _ = std::fs::remove_file(&self.temporary);
        PipelineError::parameter(format!(
            "{}: writing the video: {what}: {}",
            self.path.display(),
            err.trim()
        ))
    }
}

impl Drop for VideoWriter {
    fn drop(&mut self) {
        // Not finished (an error elsewhere): stop ffmpeg and leave no partial file.
        if self.stdin.is_some() {
            drop(self.stdin.take());
            let _ = self.child.kill();
            let _ = self.child.wait();
            let _ = std::fs::remove_file(&self.temporary);
        }
    }
}
