//! Command-line mistakes a newcomer makes, caught with a message that names the fix: a folder
//! given where an output file is expected (`--out dir/`), and a comma list written with
//! spaces (`--scale 0.5 1`). Both are usage errors (exit code 2), found before anything runs.

use std::ffi::OsStr;
use std::path::{Path, PathBuf};

use clap::error::{ContextKind, ContextValue, ErrorKind};

/// The value parser of an output file's option (`--out`, `--report`): refuses a path that
/// ends in `/` or is an existing folder, with an example file name inside that folder.
#[derive(Clone)]
pub(crate) struct OutFile(
    /// The example file name, `run.csv`.
    pub &'static str,
);

impl clap::builder::TypedValueParser for OutFile {
    type Value = PathBuf;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&clap::Arg>,
        value: &OsStr,
    ) -> Result<PathBuf, clap::Error> {
        let path = PathBuf::from(value);
        let text = value.to_string_lossy();
        let slash = text.ends_with('/') || text.ends_with(std::path::MAIN_SEPARATOR);
        if !slash && !path.is_dir() {
            return Ok(path);
        }
        let option = arg
            .and_then(clap::Arg::get_long)
            .map_or_else(|| "this option".to_owned(), |l| format!("--{l}"));
        let what = if path.is_dir() {
            "is a folder"
        } else {
            "ends in `/`, a folder"
        };
        let example = Path::new(&*text).join(self.0);
        let mut cmd = cmd.clone();
        Err(cmd.error(
            ErrorKind::InvalidValue,
            format!(
                "`{text}` {what}, but {option} takes a file name: e.g. `{option} {}`",
                example.display()
            ),
        ))
    }
}

/// The verbs' options that take one comma-separated list of numbers (`sweep --scale
/// 0.5,1,1.5`); elsewhere `--pressure-mpa` takes one value.
const COMMA_LISTS: [(&str, &str); 5] = [
    ("sweep", "--scale"),
    ("sweep", "--pressure-mpa"),
    ("sweep", "--set"),
    ("compare", "--window"),
    ("plan", "--band-hz"),
];

/// `e` restated when it is an "unexpected argument" that is the second value of a comma list
/// written with spaces (`--scale 0.5 1`): the values are one comma-separated list,
/// `--scale 0.5,1`. Any other error is returned as it is.
pub(crate) fn spaced_list(e: clap::Error) -> clap::Error {
    if e.kind() != ErrorKind::UnknownArgument {
        return e;
    }
    let Some(ContextValue::String(found)) = e.get(ContextKind::InvalidArg) else {
        return e;
    };
    let args: Vec<String> = std::env::args_os()
        .map(|a| a.to_string_lossy().into_owned())
        .collect();
    let Some(i) = args.iter().skip(1).position(|a| a == found).map(|i| i + 1) else {
        return e;
    };
    // Back over the plain values to the option they follow.
    let Some(at) = (1..i).rev().find(|&j| args[j].starts_with("--")) else {
        return e;
    };
    let (option, own) = match args[at].split_once('=') {
        Some((name, value)) => (name, Some(value)),
        None => (args[at].as_str(), None),
    };
    let verb = args.get(1).map_or("", String::as_str);
    if !COMMA_LISTS.contains(&(verb, option)) {
        return e;
    }
    let number = |v: &&str| v.split(',').all(|x| x.trim().parse::<f64>().is_ok());
    let mut values: Vec<&str> = own.into_iter().collect();
    // The values run on past the unexpected one (`--scale 0.5 1 1.5`) up to the next option.
    let end = (i..args.len())
        .find(|&j| args[j].starts_with("--"))
        .unwrap_or(args.len());
    let rest = &args[at + 1..end];
    if option == "--set" && values.is_empty() {
        // The first value is FORM.NAME=V1; the others are numbers.
        values.extend(rest.first().map(String::as_str));
        values.extend(rest.iter().skip(1).map(String::as_str).filter(number));
    } else {
        values.extend(rest.iter().map(String::as_str).filter(number));
    }
    if values.len() < 2 {
        return e;
    }
    let mut cmd = <crate::Cli as clap::CommandFactory>::command();
    if let Some(name) = args.first().map(Path::new).and_then(Path::file_name) {
        cmd = cmd.bin_name(name.to_string_lossy().into_owned());
    }
    cmd.build();
    let sub = cmd.find_subcommand_mut(verb).cloned();
    let mut cmd = sub.unwrap_or(cmd);
    cmd.error(
        ErrorKind::UnknownArgument,
        format!(
            "unexpected argument '{found}': {option} takes one comma-separated list, without \
             spaces: `{option} {}`",
            values.join(",")
        ),
    )
}
