//! A small, strict argument parser: `--flag value`, `--flag=value`, boolean
//! switches and positionals. Unknown flags are errors that list the known ones.

use super::CliError;

/// Parsed arguments of one subcommand.
pub struct Args {
    values: Vec<(String, String)>,
    switches: Vec<String>,
    /// Positional arguments in order.
    pub positionals: Vec<String>,
}

/// What a subcommand accepts.
pub struct Spec {
    /// Subcommand name, for messages.
    pub command: &'static str,
    /// Flags that take a value (without the leading `--`).
    pub valued: &'static [&'static str],
    /// Flags that take no value.
    pub switches: &'static [&'static str],
}

impl Args {
    /// Parse `raw` against `spec`.
    pub fn parse(raw: &[String], spec: &Spec) -> Result<Args, CliError> {
        let mut args = Args {
            values: Vec::new(),
            switches: Vec::new(),
            positionals: Vec::new(),
        };
        let mut i = 0;
        while i < raw.len() {
            let a = &raw[i];
            if a == "--" {
                args.positionals.extend(raw[i + 1..].iter().cloned());
                break;
            }
            if let Some(flag) = a.strip_prefix("--") {
                let (name, inline) = match flag.split_once('=') {
                    Some((n, v)) => (n, Some(v.to_string())),
                    None => (flag, None),
                };
                if spec.switches.contains(&name) {
                    if inline.is_some() {
                        return Err(CliError::usage(
                            spec.command,
                            format!("--{name} takes no value"),
                        ));
                    }
                    args.switches.push(name.to_string());
                } else if spec.valued.contains(&name) {
                    let value = match inline {
                        Some(v) => v,
                        None => {
                            i += 1;
                            raw.get(i).cloned().ok_or_else(|| {
                                CliError::usage(spec.command, format!("--{name} needs a value"))
                            })?
                        }
                    };
                    args.values.push((name.to_string(), value));
                } else {
                    let mut known: Vec<String> = spec
                        .valued
                        .iter()
                        .chain(spec.switches)
                        .map(|k| format!("--{k}"))
                        .collect();
                    known.sort();
                    return Err(CliError::usage(
                        spec.command,
                        format!("unknown option --{name} (known: {})", known.join(", ")),
                    ));
                }
            } else if a == "-o" {
                i += 1;
                let v = raw
                    .get(i)
                    .cloned()
                    .ok_or_else(|| CliError::usage(spec.command, "-o needs a file name"))?;
                args.values.push(("output".to_string(), v));
            } else {
                args.positionals.push(a.clone());
            }
            i += 1;
        }
        Ok(args)
    }

    /// The last value given for `--name`.
    pub fn value(&self, name: &str) -> Option<&str> {
        self.values
            .iter()
            .rev()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }

    /// Every value given for `--name`, in order (for repeatable flags).
    pub fn values(&self, name: &str) -> Vec<&str> {
        self.values
            .iter()
            .filter(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
            .collect()
    }

    /// Whether the switch `--name` was given.
    pub fn switch(&self, name: &str) -> bool {
        self.switches.iter().any(|s| s == name)
    }

    /// The value of `--name` parsed as `T`, or `default`.
    pub fn parsed<T: std::str::FromStr>(
        &self,
        command: &str,
        name: &str,
        default: T,
    ) -> Result<T, CliError> {
        match self.value(name) {
            None => Ok(default),
            Some(v) => v.parse().map_err(|_| {
                CliError::usage(command, format!("--{name}: '{v}' is not a valid value"))
            }),
        }
    }
}
