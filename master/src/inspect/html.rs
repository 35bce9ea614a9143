//! HTML to plain text for `shipsim inspect --doc`: the FMU's `documentation/index.html`
//! (FMI 2.0, sec. 2.2.1 and 2.3) read in a terminal.
//!
//! A small routine rather than an HTML engine: the pages it is for are documentation pages
//! (headings, paragraphs, lists, tables, `<pre>`), and it needs no dependency. It drops
//! `<head>`, `<style>` and `<script>` content and comments, decodes character references
//! (named ones of HTML 4's Latin-1, symbol and special sets as far as documentation uses them,
//! and numeric ones), collapses white space outside `<pre>`, keeps `<pre>` verbatim, starts
//! block elements on their own line, marks headings and list items, separates table cells
//! with " | ", and wraps running text at a width.

/// Text of an HTML document, paragraphs wrapped at `width` columns (`<pre>` lines are not
/// wrapped).
pub fn to_text(html: &str, width: usize) -> String {
    let mut p = Parser::default();
    let mut rest = html;
    while let Some(lt) = rest.find('<') {
        p.text(&rest[..lt]);
        rest = &rest[lt..];
        if let Some(after) = rest.strip_prefix("<!--") {
            rest = after.find("-->").map_or("", |e| &after[e + 3..]);
            continue;
        }
        let Some(gt) = rest.find('>') else {
            // A '<' that opens no tag is text.
            p.text(rest);
            rest = "";
            break;
        };
        let tag = &rest[1..gt];
        rest = &rest[gt + 1..];
        if let Some(skip) = p.tag(tag) {
            // Raw-text content (style, script) up to its end tag.
            let close = format!("</{skip}");
            let end = find_ci(rest, &close).unwrap_or(rest.len());
            rest = &rest[end..];
        }
    }
    p.text(rest);
    p.finish(width)
}

/// Case-insensitive find of an ASCII needle.
fn find_ci(hay: &str, needle: &str) -> Option<usize> {
    let (h, n) = (hay.as_bytes(), needle.as_bytes());
    (0..=h.len().checked_sub(n.len())?).find(|&i| h[i..i + n.len()].eq_ignore_ascii_case(n))
}

/// Lines that follow each other without a blank line.
#[derive(Clone, Copy, PartialEq)]
enum Row {
    Table,
    List,
}

/// One block of output: running text (wrapped) or preformatted lines.
enum Block {
    Text(String),
    Pre(String),
}

#[derive(Default)]
struct Parser {
    blocks: Vec<Block>,
    /// The running text of the current block.
    line: String,
    pre: Option<String>,
    /// Inside `<head>` (its text, the title, is not part of the page's body).
    in_head: bool,
    /// Inside a table row: the next cell gets a separator.
    cells_in_row: usize,
    /// Nesting of ordered (Some(next number)) and unordered lists.
    lists: Vec<Option<usize>>,
}

impl Parser {
    fn text(&mut self, raw: &str) {
        if self.in_head || raw.is_empty() {
            return;
        }
        // Control characters (raw or as `&#27;`, `&#x9b;`, ...) would reach the terminal as
        // escape sequences from an FMU's page: shown as U+FFFD, as HTML itself treats most of
        // them; tab and line ends stay.
        let decoded: String = decode_entities(raw)
            .chars()
            .map(|c| match c {
                '\t' | '\n' | '\r' => c,
                c if c.is_control() => '\u{fffd}',
                c => c,
            })
            .collect();
        match &mut self.pre {
            Some(pre) => pre.push_str(&decoded),
            None => {
                // HTML's white space is ASCII; a decoded &nbsp; stays.
                let ws = |c: char| c.is_ascii_whitespace();
                for (i, word) in decoded.split(ws).enumerate() {
                    let space_before = i > 0 || raw.starts_with(ws);
                    if space_before && !self.line.is_empty() && !self.line.ends_with(' ') {
                        self.line.push(' ');
                    }
                    self.line.push_str(word);
                }
            }
        }
    }

    /// Ends the current block of running text.
    fn block(&mut self) {
        let t = self.line.trim().to_string();
        self.line.clear();
        if !t.is_empty() {
            self.blocks.push(Block::Text(t));
        }
    }

    /// A tag (without the angle brackets); returns the element whose raw content to skip.
    fn tag(&mut self, tag: &str) -> Option<&'static str> {
        let closing = tag.starts_with('/');
        let name: String = tag
            .trim_start_matches('/')
            .chars()
            .take_while(|c| c.is_ascii_alphanumeric())
            .collect::<String>()
            .to_ascii_lowercase();
        if self.pre.is_some() && !(closing && name == "pre") {
            return None;
        }
        match (name.as_str(), closing) {
            ("head", c) => self.in_head = !c,
            ("style", false) => return Some("style"),
            ("script", false) => return Some("script"),
            ("pre", false) => {
                self.block();
                self.pre = Some(String::new());
            }
            ("pre", true) => {
                let pre = self.pre.take().unwrap_or_default();
                let pre = pre
                    .strip_prefix('\n')
                    .unwrap_or(&pre)
                    .trim_end()
                    .to_string();
                self.blocks.push(Block::Pre(pre));
            }
            ("h1" | "h2" | "h3" | "h4" | "h5" | "h6", false) => {
                self.block();
                let level = name[1..].parse::<usize>().unwrap_or(1);
                self.line.push_str(&"#".repeat(level));
                self.line.push(' ');
            }
            ("ul", false) => {
                self.block();
                self.lists.push(None);
            }
            ("ol", false) => {
                self.block();
                self.lists.push(Some(1));
            }
            ("ul" | "ol", true) => {
                self.block();
                self.lists.pop();
            }
            ("li", false) => {
                self.block();
                let indent = "  ".repeat(self.lists.len().saturating_sub(1));
                let mark = match self.lists.last_mut() {
                    Some(Some(n)) => {
                        *n += 1;
                        format!("{}.", *n - 1)
                    }
                    _ => "-".to_string(),
                };
                self.line = format!("{indent}{mark} ");
            }
            ("tr", false) => {
                self.block();
                self.cells_in_row = 0;
            }
            ("td" | "th", false) => {
                if self.cells_in_row > 0 {
                    self.line.push_str(" | ");
                }
                self.cells_in_row += 1;
            }
            ("br", _) => self.block(),
            (
                "p" | "div" | "table" | "tr" | "h1" | "h2" | "h3" | "h4" | "h5" | "h6" | "li"
                | "dl" | "dt" | "dd" | "blockquote" | "section" | "body" | "hr",
                _,
            ) => self.block(),
            _ => {}
        }
        None
    }

    fn finish(mut self, width: usize) -> String {
        self.block();
        if let Some(pre) = self.pre.take() {
            self.blocks.push(Block::Pre(pre));
        }
        let mut out = String::new();
        // Table rows follow each other, and list items, without a blank line.
        let mut previous_row = None;
        for b in &self.blocks {
            match b {
                Block::Pre(t) => {
                    out.push('\n');
                    out.push_str(t);
                    out.push_str("\n\n");
                    previous_row = None;
                }
                Block::Text(t) => {
                    let row = match () {
                        _ if t.contains(" | ") => Some(Row::Table),
                        _ if t.starts_with("- ") || t.starts_with(' ') => Some(Row::List),
                        _ => None,
                    };
                    if !(out.is_empty()
                        || out.ends_with("\n\n")
                        || row.is_some() && row == previous_row)
                    {
                        out.push('\n');
                    }
                    out.push_str(&wrap(t, width));
                    out.push('\n');
                    previous_row = row;
                }
            }
        }
        out.trim_start_matches('\n').trim_end().to_string() + "\n"
    }
}

/// Running text wrapped at `width` columns on spaces (a longer word gets its own line);
/// continuation lines of a list item are indented under its text.
pub fn wrap(text: &str, width: usize) -> String {
    let indent = match text.find("- ") {
        Some(i) if text[..i].trim().is_empty() => i + 2,
        _ => 0,
    };
    let mut out = String::new();
    let mut col = 0;
    for word in text.split(' ').filter(|w| !w.is_empty()) {
        let n = word.chars().count();
        if col > 0 && col + 1 + n > width {
            out.push('\n');
            out.push_str(&" ".repeat(indent));
            col = indent;
        } else if col > 0 {
            out.push(' ');
            col += 1;
        }
        out.push_str(word);
        col += n;
    }
    out
}

/// Decodes character references: `&name;`, `&#NNN;` and `&#xHH;`. An unknown or unterminated
/// reference is kept as written.
pub fn decode_entities(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(amp) = rest.find('&') {
        out.push_str(&rest[..amp]);
        rest = &rest[amp..];
        let end = rest[1..]
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '#'))
            .map(|i| i + 1);
        let decoded = match end {
            Some(e) if rest[e..].starts_with(';') => entity(&rest[1..e]).map(|c| (c, e + 1)),
            _ => None,
        };
        match decoded {
            Some((c, len)) => {
                out.push(c);
                rest = &rest[len..];
            }
            None => {
                out.push('&');
                rest = &rest[1..];
            }
        }
    }
    out.push_str(rest);
    out
}

fn entity(name: &str) -> Option<char> {
    if let Some(num) = name.strip_prefix('#') {
        let code = match num.strip_prefix(['x', 'X']) {
            Some(hex) => u32::from_str_radix(hex, 16).ok()?,
            None => num.parse::<u32>().ok()?,
        };
        return char::from_u32(code);
    }
    Some(match name {
        "amp" => '&',
        "lt" => '<',
        "gt" => '>',
        "quot" => '"',
        "apos" => '\'',
        "nbsp" => '\u{a0}',
        "deg" => '°',
        "plusmn" => '±',
        "times" => '×',
        "divide" => '÷',
        "middot" => '·',
        "micro" => 'µ',
        "sup2" => '²',
        "sup3" => '³',
        "frac12" => '½',
        "ndash" => '–',
        "mdash" => '—',
        "hellip" => '…',
        "lsquo" => '‘',
        "rsquo" => '’',
        "ldquo" => '“',
        "rdquo" => '”',
        "minus" => '−',
        "le" => '≤',
        "ge" => '≥',
        "ne" => '≠',
        "asymp" => '≈',
        "infin" => '∞',
        "radic" => '√',
        "sum" => '∑',
        "int" => '∫',
        "part" => '∂',
        "rarr" => '→',
        "larr" => '←',
        "alpha" => 'α',
        "beta" => 'β',
        "gamma" => 'γ',
        "delta" => 'δ',
        "Delta" => 'Δ',
        "epsilon" => 'ε',
        "zeta" => 'ζ',
        "eta" => 'η',
        "theta" => 'θ',
        "lambda" => 'λ',
        "mu" => 'μ',
        "nu" => 'ν',
        "xi" => 'ξ',
        "pi" => 'π',
        "rho" => 'ρ',
        "sigma" => 'σ',
        "Sigma" => 'Σ',
        "tau" => 'τ',
        "phi" => 'φ',
        "psi" => 'ψ',
        "omega" => 'ω',
        "Omega" => 'Ω',
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strips_tags_decodes_references_and_keeps_pre() {
        let html = "<!DOCTYPE html><html><head><title>T</title><style>p{color:red}</style></head>\
            <body><h1>Waves</h1><p>A &amp; B &lt;c&gt;\n  d&#233;j&#xE0; vu,&nbsp;5&deg;\
            <!-- hidden <b>x</b> --> <b>bold</b>&unknown; &amp</p>\
            <pre>\nline 1\n  line  2 &lt;x&gt;\n</pre><ul><li>one</li><li>two</li></ul>\
            <table><tr><th>name</th><th>unit</th></tr><tr><td>a</td><td>m</td></tr></table>\
            <script>var s = '<p>no</p>';</script>end</body></html>";
        let t = to_text(html, 100);
        assert_eq!(
            t,
            "# Waves\n\nA & B <c> déjà vu,\u{a0}5° bold&unknown; &amp\n\nline 1\n  line  2 <x>\n\n\
             - one\n- two\n\nname | unit\na | m\n\nend\n"
        );
    }

    #[test]
    fn control_characters_do_not_reach_the_terminal() {
        let t = to_text("<p>a&#27;]0;x&#7;b\u{1b}[2J c&#x9b;d\u{9b}e\tf</p>", 100);
        assert!(
            !t.chars().any(|c| c.is_control() && c != '\n' && c != '\t'),
            "{t:?}"
        );
        assert_eq!(
            t,
            "a\u{fffd}]0;x\u{fffd}b\u{fffd}[2J c\u{fffd}d\u{fffd}e f\n"
        );
    }

    #[test]
    fn wraps_at_the_width() {
        let w = wrap("aaa bbb ccc dddddddddd e", 7);
        assert_eq!(w, "aaa bbb\nccc\ndddddddddd\ne");
        assert_eq!(wrap("- one two three", 9), "- one two\n  three");
    }
}
